function step(dt) error(nil) end --!
