"""Joint scenario specs the joint and MuJoCo tests share."""

from __future__ import annotations

import copy
import math


def on_levers(spec: dict) -> dict:
    """``spec``'s pair with each muscle on a lever: from an anchor 0.35 m from the joint on the base to a point
    0.03 m from it on the link, the arms at right angles at angle zero, a tendon that makes it 20 mm
    contracted there (0.3 m muscle, path sqrt(0.03^2 + 0.35^2)); the limits +-0.5 rad."""
    spec = copy.deepcopy(spec)
    tendon = math.hypot(0.03, 0.35) - (0.3 - 0.02)
    for table in spec["muscle"]:
        for key in ("radius_m", "x_at_zero_m"):
            table.pop(key)
        table.update(attachment="lever", link_attach_m=0.03, base_attach_m=0.35, angle_at_zero_rad=math.pi / 2,
                     tendon_length_m=tendon)
    spec["joint"].update(theta_min_rad=-0.5, theta_max_rad=0.5)
    return spec
