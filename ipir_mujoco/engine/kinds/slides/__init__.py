"""The slide model's kind: the modules on two slides, a joint-limit ratchet, velocity-triggered locks or no clutch."""
