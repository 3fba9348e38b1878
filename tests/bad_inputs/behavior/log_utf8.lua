function step(dt)
  log('bytes \xff\xfe \0 \27[2J escape')
end
