"""The robot room: a robot's config (one field-checked TOML file), its calibration (angles <-> ticks,
built once per config), its servos' gains, and the walk settings the gait room takes from it."""
