return require('no_such_type_xyz') --!
