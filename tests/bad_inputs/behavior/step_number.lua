step = 42 --!
