"""A parameter set to a MuJoCo model (``MjSpec`` to ``MjModel``): the slide model, the carriages of finite grip,
the wheeled model, the pipe's walls. The engine's lowest folder: it imports no other folder of the engine."""

# m: the far side of every one-way limit (the slides', the carriages', the rolls'), far beyond any run (1000 km):
# only the side the engine moves ever acts
RANGE_FAR = 1e6
