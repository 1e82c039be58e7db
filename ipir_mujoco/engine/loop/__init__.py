"""The stepping loop of a serial run (compiled in ``_stepper.c`` where it can be), the constraint rows it reads,
the recorder, the accuracy monitor, the clutch controller protocol the loop calls and the servo's ticks. It names
no model kind; of the engine it imports only :mod:`..builders`."""
