step = "go" --!
