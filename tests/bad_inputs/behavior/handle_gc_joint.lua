function step()
  getmetatable(module.joint("pitch")).__gc = function() while true do end end --!
end
