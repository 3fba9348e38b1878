function step(dt) error('bytes \xff\xfe\xc3\x28 end') end --!
