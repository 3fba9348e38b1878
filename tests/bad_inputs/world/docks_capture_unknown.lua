world.set{duration = 0.2}
world.docks{capture = "glue"}
