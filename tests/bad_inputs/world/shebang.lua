#!/usr/bin/env rm3d
world.set{duration = 0.1}
