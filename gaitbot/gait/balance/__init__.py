"""The balanced 3D walk: a ZMP reference from the plan, the centre of mass by Kajita's preview control,
the pelvis placed on the whole body's centre of mass, legs by the 6-joint IK (docs/balance.md)."""
