function step(dt) module = nil; sim = nil; log = nil; print = nil; error = nil; tostring = nil; pcall = nil end
