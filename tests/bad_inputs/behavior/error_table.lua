function step(dt) error({code = 7}) end --!
