"""One frame's body placement in plain floats: the online walker's hot path.

Why a second implementation: numpy costs microseconds per call whatever the array size, and placing
the pelvis so that the whole CoM is on the plan takes a few IK + CoM evaluations per frame; with numpy
that is ~1.5 ms a frame, over the 1 ms budget. For the straight walk the balanced walker plans (root
upright, soles flat, no yaw) the leg IK and the link CoMs reduce to a few rotations about x and y,
done here with the math module (~10x faster). tests/gait/test_balance_walker.py checks it against the
vectorised gaitbot.gait.kinematics6 / gaitbot.gait.mass to 1e-12.

Turned feet (steering): the torso turns by the mean of the feet's yaws and each hip yaw joint turns its
foot by the rest; a leg's links then turn about its hip point, the rest is the flat-foot algebra in the
foot's frame. ``yaws=None`` (or both 0) keeps the straight walk's arithmetic exactly.
"""

from __future__ import annotations

import math

from gaitbot.gait.body import LEG_LINKS, SIDE_SIGN, BodyModel
from gaitbot.gait.joints import SIDES
from gaitbot.gait.mass import GRAVITY_M_S2


class FlatFootBody:
    """Leg IK, whole-body CoM and gravity torques for an upright root and flat, unturned feet."""

    def __init__(self, body: BodyModel) -> None:
        g = body.geometry
        self.l1, self.l2 = g.thigh_m, g.shank_m
        self.hips = {s: tuple(float(v) for v in g.hip_in_root(s)) for s in SIDES}
        self.torso_kg = body.torso.mass_kg
        self.torso_com = tuple(float(v) for v in body.torso.com_m)
        self.link_kg = [body.leg_links[n].mass_kg for n in LEG_LINKS]
        self.link_com = {s: [tuple(float(v) for v in body.leg_link(n, s).com_m) for n in LEG_LINKS] for s in SIDES}
        self.total_kg = self.torso_kg + 2 * sum(self.link_kg)
        self._last_q, self._last_points = None, []

    def leg_ik(self, side: str, rx: float, ry: float, rz: float, gamma: float = 0.0) -> list[float]:
        """One leg's six angles for r = hip - ankle (root frame); the foot flat, turned by gamma (rad)
        from the root's x axis (the hip yaw joint's turn, toe outward positive on either leg)."""
        s = SIDE_SIGN[side]
        if gamma != 0.0:  # r in the foot's frame; the hip yaw joint turns the rest of the leg
            c, sn = math.cos(gamma), math.sin(gamma)
            rx, ry = c * rx + sn * ry, -sn * rx + c * ry
        l1, l2 = self.l1, self.l2
        cos_knee = (rx * rx + ry * ry + rz * rz - l1 * l1 - l2 * l2) / (2 * l1 * l2)
        knee = math.acos(min(1.0, max(-1.0, cos_knee)))
        a6 = math.atan(ry / rz)
        vz = math.copysign(math.hypot(ry, rz), rz)
        a5 = -math.atan2(l1 * math.sin(knee), l1 * math.cos(knee) + l2) - math.atan2(rx, vz)
        # flat foot, no yaw: hip rotation Rx(-a6) Ry(-(knee + a5)): yaw 0, roll -a6, pitch -(knee + a5)
        return [s * gamma, -s * a6, knee + a5, knee, -a5, s * a6]

    def link_points(self, side: str, q: list[float]) -> list[tuple[float, float, float]]:
        """Each leg link's CoM (root frame) for that leg's angles q (hip yaw turning them about the hip)."""
        points = self._leg(side, q)[0]
        if q[0] == 0.0:
            return points
        gamma = SIDE_SIGN[side] * q[0]
        c, sn = math.cos(gamma), math.sin(gamma)
        hx, hy, _ = self.hips[side]
        return [(hx + c * (px - hx) - sn * (py - hy), hy + sn * (px - hx) + c * (py - hy), pz) for px, py, pz in points]

    def _leg(self, side: str, q: list[float]):
        """(link CoMs, knee point, ankle point) in the root frame."""
        s = SIDE_SIGN[side]
        hx, hy, hz = self.hips[side]
        cr, sr = math.cos(s * q[1]), math.sin(s * q[1])
        # Rx(s roll), then pitch about y: thigh -p, shank -p+k, ankle -p+k-a; the foot adds Rx(s ankle_roll)
        p2 = -q[2]
        p3 = p2 + q[3]
        p4 = p3 - q[4]
        c2, s2, c3, s3, c4, s4 = math.cos(p2), math.sin(p2), math.cos(p3), math.sin(p3), math.cos(p4), math.sin(p4)
        (x0, y0, z0), (x1, y1, z1), (x2, y2, z2), (x3, y3, z3), (x4, y4, z4), (x5, y5, z5) = self.link_com[side]
        l1, l2 = self.l1, self.l2
        kx, ky, kz = hx - l1 * s2, hy + l1 * sr * c2, hz - l1 * cr * c2
        ax, ay, az = kx - l2 * s3, ky + l2 * sr * c3, kz - l2 * cr * c3
        ca, sa = math.cos(s * q[5]), math.sin(s * q[5])
        y5, z5 = ca * y5 - sa * z5, sa * y5 + ca * z5
        out = [(hx + x0, hy + y0, hz + z0),
               (hx + x1, hy + cr * y1 - sr * z1, hz + sr * y1 + cr * z1)]
        for (ox, oy, oz), (cb, sb), (cx, cy, cz) in (((hx, hy, hz), (c2, s2), (x2, y2, z2)),
                                                      ((kx, ky, kz), (c3, s3), (x3, y3, z3)),
                                                      ((ax, ay, az), (c4, s4), (x4, y4, z4)),
                                                      ((ax, ay, az), (c4, s4), (x5, y5, z5))):
            pz = -sb * cx + cb * cz
            out.append((ox + cb * cx + sb * cz, oy + cr * cy - sr * pz, oz + sr * cy + cr * pz))
        return out, (kx, ky, kz), (ax, ay, az)

    def gravity_torques(self, q, share_left: float, cops) -> list[float]:
        """As MassModel.gravity_torques for one frame: the 12 joint torques (N m) holding the pose;
        cops[side index] = (x, y) of each foot's centre of pressure in the root frame; a turned foot (hip yaw
        q[0] or q[6] not 0) turns its leg's links and joint axes about the hip."""
        g = GRAVITY_M_S2
        weight = self.total_kg * g
        out = []
        for i, side in enumerate(SIDES):
            s = SIDE_SIGN[side]
            share = share_left if side == "left" else 1.0 - share_left
            leg = q[6 * i:6 * i + 6]
            points, knee, ankle = self._leg(side, leg)
            cr, sr = math.cos(s * leg[1]), math.sin(s * leg[1])
            b5 = -leg[2] + leg[3] - leg[4]
            axes = ((0.0, 0.0), (s, 0.0), (0.0, -cr), (0.0, cr), (0.0, -cr), (s * math.cos(b5), s * sr * math.sin(b5)))
            if leg[0] != 0.0:  # the hip yaw joint turns the rest of the leg (points and axes) about the hip
                cg, sg = math.cos(s * leg[0]), math.sin(s * leg[0])
                hx, hy, _ = self.hips[side]
                points = [(hx + cg * (px - hx) - sg * (py - hy), hy + sg * (px - hx) + cg * (py - hy), pz)
                          for px, py, pz in points]
                knee, ankle = ((hx + cg * (px - hx) - sg * (py - hy), hy + sg * (px - hx) + cg * (py - hy), pz)
                               for px, py, pz in (knee, ankle))
                axes = tuple((cg * ax - sg * ay, sg * ax + cg * ay) for ax, ay in axes)
            joints = (self.hips[side], self.hips[side], self.hips[side], knee, ankle, ankle)
            fx, fy = cops[i]
            for j in range(6):
                jx, jy = joints[j][0], joints[j][1]
                # the moment of vertical forces f at (x, y) about the joint: (f (y - jy), -f (x - jx), 0)
                mx = share * weight * (fy - jy)
                my = -share * weight * (fx - jx)
                for k in range(j, 6):
                    f = -self.link_kg[k] * g
                    mx += f * (points[k][1] - jy)
                    my -= f * (points[k][0] - jx)
                out.append(-(mx * axes[j][0] + my * axes[j][1]))
        return out

    def legs(self, root, ankles, yaws=None) -> list[float]:
        """12 angles for an upright root at ``root`` (x, y, z) and flat feet at ankles[side index], turned
        by yaws[side index] (rad; the torso by their mean)."""
        q = []
        if yaws is None or (yaws[0] == 0.0 and yaws[1] == 0.0):
            for i, side in enumerate(SIDES):
                hx, hy, hz = self.hips[side]
                ax, ay, az = ankles[i]
                q += self.leg_ik(side, root[0] + hx - ax, root[1] + hy - ay, root[2] + hz - az)
            return q
        psi = 0.5 * (yaws[0] + yaws[1])
        c, sn = math.cos(psi), math.sin(psi)
        for i, side in enumerate(SIDES):
            hx, hy, hz = self.hips[side]
            dx, dy = ankles[i][0] - root[0], ankles[i][1] - root[1]
            q += self.leg_ik(side, hx - (c * dx + sn * dy), hy - (-sn * dx + c * dy), root[2] + hz - ankles[i][2],
                             yaws[i] - psi)
        return q

    def world_points(self, root, q, yaws=None) -> list[tuple[float, float, float]]:
        """The torso's and the 12 leg links' CoMs in the world (the torso turned by the feet's mean yaw)."""
        if self._last_q is q:  # the placement's last pose (com_in_root has the points)
            local = [self.torso_com] + self._last_points
        else:
            local = [self.torso_com]
            for k, side in enumerate(SIDES):
                local += self.link_points(side, q[6 * k:6 * k + 6])
        psi = 0.0 if yaws is None else 0.5 * (yaws[0] + yaws[1])
        if psi == 0.0:
            return [(root[0] + p[0], root[1] + p[1], root[2] + p[2]) for p in local]
        c, sn = math.cos(psi), math.sin(psi)
        return [(root[0] + c * p[0] - sn * p[1], root[1] + sn * p[0] + c * p[1], root[2] + p[2]) for p in local]

    def com_in_root(self, q) -> tuple[float, float, float]:
        m = self.torso_kg
        x, y, z = (m * c for c in self.torso_com)
        points = self.link_points("left", q[0:6]) + self.link_points("right", q[6:12])
        for kg, (px, py, pz) in zip(self.link_kg + self.link_kg, points):
            x += kg * px
            y += kg * py
            z += kg * pz
        self._last_q, self._last_points = q, points  # world_points of the same pose reuses them
        return x / self.total_kg, y / self.total_kg, z / self.total_kg

    def place(self, com_x: float, com_y: float, ankles, root_z: float, guess_dx: float, guess_dy: float,
              slope: float, tolerance_m: float, max_iterations: int, yaws=None):
        """Root (x, y, z), angles and residual putting the whole CoM at (com_x, com_y) (as
        gaitbot.gait.balance.placement.WholeBody.place, one frame; yaws: the feet's, rad)."""
        psi = 0.0 if yaws is None else 0.5 * (yaws[0] + yaws[1])
        c, sn = math.cos(psi), math.sin(psi)
        rx, ry = com_x + guess_dx, com_y + guess_dy
        sx = sy = slope
        last = None
        residual = math.inf
        q: list[float] = []
        for _ in range(max_iterations):
            q = self.legs((rx, ry, root_z), ankles, yaws)
            cx, cy, _ = self.com_in_root(q)
            if psi != 0.0:
                cx, cy = c * cx - sn * cy, sn * cx + c * cy
            cx, cy = rx + cx, ry + cy
            ex, ey = com_x - cx, com_y - cy
            residual = max(abs(ex), abs(ey))
            if residual < tolerance_m:
                break
            if last is not None:  # secant slopes, where the root moved enough to measure them
                if abs(rx - last[0]) > 1e-9:
                    sx = (cx - last[2]) / (rx - last[0])
                if abs(ry - last[1]) > 1e-9:
                    sy = (cy - last[3]) / (ry - last[1])
            last = (rx, ry, cx, cy)
            rx += ex / sx
            ry += ey / sy
        return (rx, ry, root_z), q, residual
