world.set{duration = 0.2}
require('require_self') --!
