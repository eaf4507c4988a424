#!/usr/bin/env python3
"""Writes params/test-bicycle.toml and params/test-bicycle-light-rider.toml.

Where the seed paper (Table 1) gives a value it is used as printed. The rest
comes from measured data published with BicycleParameters (J. K. Moore,
2012 dissertation "Human control of a bicycle"): the Batavus Browser, a
Dutch city bicycle with 28 inch wheels, and its rider Jason, split into the
legs (rigid with the frame) and the upper body (head, arms, trunk) as in
Moore's rider-lean model. The Browser's masses are scaled to the seed's
14.5 kg bicycle, Jason (72 kg) to the seed's rider. Tyres: Dressel (2013)
measurements of bicycle tyres, as quoted in the issue. Only the
steering-head stiffness and damping are tuned (the literature leaves them
open), as the seed paper tuned its steering-head stiffness.

Run: python3 scripts/derive_test_bicycle.py  (from the crate directory)
"""
import math

MOORE = "Moore 2012 (BicycleParameters data)"

# Batavus Browser, BrowserBenchmark.txt (BicycleParameters): m, x, z, Ixx, Ixz, Iyy, Izz.
BROWSER_B = (9.9, 0.274, -0.538, 0.5296, -0.1163, 1.3164, 0.7568)
BROWSER_H = (3.2, 0.867, -0.748, 0.2534, -0.0720, 0.2458, 0.0956)
BROWSER_R = (3.1, 0.341, 0.0904, 0.1524)  # m, r, Ixx, Iyy
BROWSER_F = (2.0, 0.344, 0.0884, 0.1492)
BROWSER_W = 1.121
# Jason on the Browser, rider alone (JasonBrowserBenchmark.txt) and the
# Browser's rear frame with Jason's legs (meijaard2007_browser_jasonlegs).
JASON = (72.0, 0.2909, -1.1091, 7.9985, -1.9272, 8.0689, 2.3624)
FRAME_AND_LEGS = (33.044, 0.374570794542, -0.681592725778, 2.18917391377,
                  -0.27087131147, 2.9922715238, 1.61787114693)

# Seed paper, Table 1.
BICYCLE_KG = 14.5
DEVICES_KG = 3.5
WHEELBASE = 1.095
HEAD_ANGLE_DEG = 71.0
TRAIL = 0.0709
RIDER_KG = 83.0


def shift(body, dx):
    m, x, z, ixx, ixz, iyy, izz = body
    return (m, x + dx, z, ixx, ixz, iyy, izz)


def scale(body, k):
    m, x, z, ixx, ixz, iyy, izz = body
    return (m * k, x, z, ixx * k, ixz * k, iyy * k, izz * k)


def combine(a, b, sign=1.0):
    """a + b (sign 1) or a - b (sign -1), parallel axes in the x-z plane."""
    ma, xa, za, *ia = a
    mb, xb, zb, *ib = b
    m = ma + sign * mb
    x = (ma * xa + sign * mb * xb) / m
    z = (ma * za + sign * mb * zb) / m

    def about(mass, bx, bz, i):
        dx, dz = bx - x, bz - z
        ixx, ixz, iyy, izz = i
        return (ixx + mass * dz * dz, ixz - mass * dx * dz,
                iyy + mass * (dx * dx + dz * dz), izz + mass * dx * dx)
    pa = about(ma, xa, za, ia)
    pb = about(mb, xb, zb, ib)
    return (m, x, z, *[p + sign * q for p, q in zip(pa, pb)])


def q(value, unit, source):
    return f'{{ value = {value:.6g}, unit = "{unit}", source = "{source}" }}'


def body_lines(name, body, source):
    m, x, z, ixx, ixz, iyy, izz = body
    assert m > 0 and ixx > 0 and iyy > 0 and izz > 0 and ixx * izz > ixz ** 2, name
    return [f"[{name}]",
            f"x = {q(x, 'm', source)}",
            f"z = {q(z, 'm', source)}",
            f"mass = {q(m, 'kg', source)}",
            f"inertia_xx = {q(ixx, 'kg m^2', source)}",
            f"inertia_xz = {q(ixz, 'kg m^2', source)}",
            f"inertia_yy = {q(iyy, 'kg m^2', source)}",
            f"inertia_zz = {q(izz, 'kg m^2', source)}", ""]


def wheel_lines(name, wheel, k, source):
    m, r, ixx, iyy = wheel
    return [f"[{name}]",
            f"radius = {q(r, 'm', source)}",
            f"mass = {q(m * k, 'kg', source)}",
            f"inertia_xx = {q(ixx * k, 'kg m^2', source)}",
            f"inertia_yy = {q(iyy * k, 'kg m^2', source)}", ""]


def tyre_lines(name):
    dressel = "Dressel 2013 bicycle tyre measurements (as quoted in the issue)"
    return [f"[{name}]",
            f"cornering_stiffness = {q(11.5, '1/rad', dressel + ', normalised cornering stiffness')}",
            f"camber_stiffness = {q(0.57, '1/rad', dressel + ', normalised camber stiffness')}",
            f"relaxation_length = {q(0.175, 'm', dressel + ', relaxation length')}",
            f"aligning_coefficient = {q(11.5 * 0.013, 'm/rad', 'pneumatic trail 13 mm (brush model a/3, Pacejka 2012 ch. 3, half contact length 40 mm, estimated) times the cornering stiffness')}",
            f"twisting_coefficient = {q(0.01, 'm/rad', 'estimate: small against the aligning moment, as in Pacejka 2012 ch. 11 motorcycle tyres')}",
            f"overturning_coefficient = {q(0.0175, 'm/rad', 'crown radius: half the 35 mm tyre width (estimated), M_x = -N rho gamma')}", ""]


def write(path, name, rider_kg, head_stiffness, head_damping):
    k_bike = BICYCLE_KG / (BROWSER_B[0] + BROWSER_H[0] + BROWSER_R[0] + BROWSER_F[0])
    dx = WHEELBASE - BROWSER_W
    legs = combine(FRAME_AND_LEGS, BROWSER_B, -1.0)
    torso = combine(JASON, legs, -1.0)
    k_rider = rider_kg / JASON[0]
    # Devices on the rear rack: a 0.3 x 0.2 x 0.15 m box above the rear axle.
    devices = (DEVICES_KG, -0.05, -0.45, DEVICES_KG * (0.2**2 + 0.15**2) / 12, 0.0,
               DEVICES_KG * (0.3**2 + 0.15**2) / 12, DEVICES_KG * (0.3**2 + 0.2**2) / 12)
    rear = combine(combine(scale(BROWSER_B, k_bike), scale(legs, k_rider)), devices)
    # The front frame split at the steering head: the fork below it as a
    # 1.0 kg, 0.35 m rod from the crown to the axle (estimated).
    lam = math.radians(90.0 - HEAD_ANGLE_DEG)
    twist_z = -0.62
    crown_x = WHEELBASE + TRAIL + twist_z * math.tan(lam)
    fork_m, fork_l = 1.0, 0.35
    fork = (fork_m, 0.5 * (crown_x + WHEELBASE), 0.5 * (twist_z - BROWSER_F[1]),
            fork_m * fork_l**2 / 12, 0.0, fork_m * fork_l**2 / 12, 0.002)
    front_upper = combine(shift(scale(BROWSER_H, k_bike), dx), fork, -1.0)
    hip_z = -0.93
    lines = [
        f"# Written by scripts/derive_test_bicycle.py: every value's derivation is there.",
        f'name = "{name}"',
        'model = "wobble"',
        'source = "Seed paper Table 1 where given; Batavus Browser and rider Jason (Moore 2012, BicycleParameters) scaled to it; tyres from Dressel 2013"',
        "",
        "[geometry]",
        f"wheelbase = {q(WHEELBASE, 'm', 'seed paper, Table 1')}",
        f"trail = {q(TRAIL, 'm', 'seed paper, Table 1')}",
        f"steer_axis_tilt = {q(90.0 - HEAD_ANGLE_DEG, 'deg', 'seed paper, Table 1: head angle 71 deg')}",
        f"gravity = {q(9.81, 'm/s^2', 'standard')}",
        "",
    ]
    lines += wheel_lines("rear_wheel", BROWSER_R, k_bike, f"{MOORE}: Browser rear wheel (28 in), mass scaled to the 14.5 kg bicycle")
    lines += wheel_lines("front_wheel", BROWSER_F, k_bike, f"{MOORE}: Browser front wheel (28 in), mass scaled to the 14.5 kg bicycle")
    lines += body_lines("rear_frame", rear, f"{MOORE}: Browser frame scaled to 14.5 kg, rider's legs (Jason) scaled to {rider_kg:g} kg, 3.5 kg devices on the rack (seed Table 1)")
    lines += body_lines("torso", scale(torso, k_rider), f"{MOORE}: Jason's upper body (head, arms, trunk) scaled to a {rider_kg:g} kg rider")
    lines += ["[hip]",
              f"z = {q(hip_z, 'm', 'saddle height of the Browser with Jason (estimated)')}",
              f"stiffness = {q(128.0, 'N m/rad', 'de Lorenzo 1996 passive rider lean stiffness, quoted in Moore 2012')}",
              f"damping = {q(50.0, 'N m s/rad', 'de Lorenzo 1996 passive rider lean damping, quoted in Moore 2012')}", ""]
    lines += body_lines("front_frame", front_upper, f"{MOORE}: Browser front frame scaled to 14.5 kg, less the fork")
    lines += body_lines("fork", fork, "estimate: 1.0 kg fork blades as a rod from the crown to the axle")
    lines += ["[steer_head]",
              f"z = {q(twist_z, 'm', 'lower head bearing of a 28 in trekking bicycle (estimated)')}",
              f"stiffness = {q(head_stiffness, 'N m/rad', 'tuned: wobble near 6 Hz, wobble speed near 4 m/s (the seed paper tuned it likewise)')}",
              f"damping = {q(head_damping, 'N m s/rad', 'tuned with the stiffness')}", ""]
    lines += tyre_lines("front_tyre")
    lines += tyre_lines("rear_tyre")
    with open(path, "w") as f:
        f.write("\n".join(lines))


HEAD_STIFFNESS = 3000.0
HEAD_DAMPING = 2.0
write("params/test-bicycle.toml", "Seed paper's test bicycle, 83 kg rider", RIDER_KG, HEAD_STIFFNESS, HEAD_DAMPING)
write("params/test-bicycle-light-rider.toml", "Seed paper's test bicycle, 55 kg rider", 55.0, HEAD_STIFFNESS, HEAD_DAMPING)
