"""The live drive (``gaitbot drive``): a frame source that plans each step from the latest command while the
robot walks, checks every frame before it is sent, and ends standing (docs/driving.md); and stepping.py, a planned walk walked the same way, its next foothold
moved to catch a push (``walk --feedback step``, docs/feedback.md)."""
