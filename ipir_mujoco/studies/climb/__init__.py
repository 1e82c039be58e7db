"""Climbing: the steepest incline a design climbs (its limits and runs) and, with finite grip, its traction."""
