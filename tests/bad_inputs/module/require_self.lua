return require('require_self') --!
