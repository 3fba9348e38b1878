world.set{duration = 0.2}
world.mesh{file = "../../../assets/meshes/bowl.obj", concave = true, mass = 1} --!
