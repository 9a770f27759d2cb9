"""Steering: velocity commands and the footsteps they ask for (docs/gait-model.md section 9)."""
