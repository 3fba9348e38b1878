world.set{duration = 0.2}
world.mesh{file = "no_such_mesh.obj"} --!
