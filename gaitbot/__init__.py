"""gaitbot: walking gaits for small servo bipeds.

Four rooms, data flowing one way (see docs in the README):
gait (angles over time) -> robot (calibration, limits) -> bus (packets) -> stream (60 Hz clock).
"""

__version__ = "0.1.0"
