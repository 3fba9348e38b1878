function init()
  error('init failed') --!
end
function step(dt) end
