local t = world.module_type("superbott") --!
