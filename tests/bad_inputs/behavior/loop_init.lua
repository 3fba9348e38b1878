function init()
  while true do end --!
end
