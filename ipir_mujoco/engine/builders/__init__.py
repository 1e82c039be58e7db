"""A parameter set to a MuJoCo model (``MjSpec`` to ``MjModel``): the slide model, the carriages of finite grip,
the wheeled model, the pipe's walls. The engine's lowest folder: it imports no other folder of the engine."""
