goto nowhere --!
