"""The balanced 3D walk: a ZMP reference from the plan, the centre of mass by Kajita's preview control,
the pelvis placed on the whole body's centre of mass, legs by the 6-joint IK (docs/balance.md).

    settings.py       BalanceSettings, the ``[balance]`` table
    zmp_reference.py  step timing (whole frames), foot placements, the ZMP reference points and shifts
    swing.py          the swing foot's progression and lift from the planar Boulic walker, per step length
    step_plan.py      the walk's plan frame by frame: ZMP reference, feet, load share, swing paths
    preview.py        Kajita's preview control: Riccati gains, online controller, offline filter
    placement.py      the pelvis on the whole-body CoM, the multibody ZMP, the sag feedforward (vectorised)
    flat_foot_body.py the same placement for one frame in floats (the online hot path)
    walker.py         BalancedWalker (online: append_step, next_frame, finish), generate_balanced_walk (offline)
    speed_fit.py      relaxes the walk until the servos can follow it

The robot room builds it from a config: gaitbot.robot.balanced_walk.
"""
