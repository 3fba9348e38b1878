-- Found by `require` from the behaviour's own folder (for sandbox_probe.lua).
return {answer = 42}
