error('top level failed') --!
