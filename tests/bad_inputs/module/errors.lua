error('type file failed') --!
