function step(dt) error('q " b \\ n \n t \t z \0 c \1 end') end --!
