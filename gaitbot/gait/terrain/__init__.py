"""Walking on uneven ground (Zhang 2008, docs/gait-model.md section 6): a terrain of flat treads, a
foothold planner, a Bezier pelvis whose mid-double-support points come from a two-level grid
search, and step segments that join the flat walker's through ``WalkState``."""
