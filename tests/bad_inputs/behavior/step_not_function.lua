step = 5
--!
