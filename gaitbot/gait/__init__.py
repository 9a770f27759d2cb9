"""The gait room: pure numpy, no I/O but the Trajectory file format."""
