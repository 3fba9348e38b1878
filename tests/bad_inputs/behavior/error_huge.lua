function step(dt) error(string.rep('e', 8e6)) end --!
