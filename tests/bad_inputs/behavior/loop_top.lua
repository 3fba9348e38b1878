while true do end --!
