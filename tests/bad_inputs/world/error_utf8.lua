world.set{duration = 0.2}
error('bad bytes \xff\xfe\xc3 here') --!
