"""Feeling the robot: its IMU read every frame, the torso's state estimated, the goals corrected, a fall noticed.

    imu_reader.py   ImuReader: one budgeted READ of the IMU device after each frame's goals (never waited on),
                    its faults (absent, frozen, noisy) noticed
    estimate.py     TiltEstimate: torso roll and pitch by a complementary filter of gyro and accelerometer
    feedback.py     Feedback: gyro damping (and, "full", attitude) corrections of each frame's goals, kept
                    inside every joint's position, velocity and acceleration limits; RobotFell
    capture.py      CapturePoint: the DCM's error from the tilt, and the next foothold moved toward it
                    ("step"; gaitbot.drive.stepping walks it)

A room between the stream (which calls it once a frame) and the bus (which it reads through); pure but for
that read. docs/feedback.md explains the choices and the figures.
"""
