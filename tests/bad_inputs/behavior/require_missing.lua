require('no_such_lib_xyz') --!
function step(dt) end
