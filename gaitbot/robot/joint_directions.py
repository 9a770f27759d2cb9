"""A joint's positive direction in words, for people holding the robot (gaitbot calibrate).

Names follow ``<part>_<axis>_<side>`` (``knee_pitch_left``, ``hip_roll_right``); the sign conventions are
docs/gait-model.md's: pitch joints flexion positive (hip flexion swings the thigh forward, knee flexion
bends the knee, ankle flexion lifts the toes), hip roll abduction positive (the foot away from the
midline), ankle roll in the hip roll's sense, hip yaw toes outward. Any other name gets a plain sentence.
"""

from __future__ import annotations

_WORDS = {
    ("hip", "pitch"): "swing the {side} thigh forward",
    ("knee", "pitch"): "bend the {side} knee",
    ("ankle", "pitch"): "lift the {side} toes (bend the ankle up)",
    ("hip", "roll"): "move the {side} leg outward, away from the other leg",
    ("ankle", "roll"): "tilt the {side} foot so its outer edge rises",
    ("hip", "yaw"): "turn the {side} toes outward",
}


def positive_motion(joint_name: str) -> str:
    """What to do with the robot so that ``joint_name`` moves in its positive direction, e.g.
    ``"bend the left knee"``."""
    parts = joint_name.split("_")
    if len(parts) == 3 and parts[2] in ("left", "right") and (parts[0], parts[1]) in _WORDS:
        return _WORDS[(parts[0], parts[1])].format(side=parts[2])
    return f"move {joint_name} in its positive direction"
