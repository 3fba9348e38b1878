function init()
  on_dock = {} --!
end
