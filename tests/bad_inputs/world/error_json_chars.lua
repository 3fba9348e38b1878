world.set{duration = 0.2}
error('quote " backslash \\ newline \n tab \t nul \0 end') --!
