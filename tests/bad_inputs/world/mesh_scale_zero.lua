world.set{duration = 0.2}
world.mesh{file = "../../../assets/meshes/superbot_end_plate.obj", scale = 0} --!
