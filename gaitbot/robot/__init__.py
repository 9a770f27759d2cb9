"""The robot room: robot description from config, servo models, calibration and limits."""
