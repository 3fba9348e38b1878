function step(dt) module.joint('yaw'):set_velocity(1e300) end
