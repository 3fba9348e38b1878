world.set{duration = 0.2}
require('no_such_module_xyz') --!
