#!/usr/bin/python3
"""The least swing any stop can leave from 1 s after the stick's release, within the tip
scaler's bounds (docs/sway.md, "The swing 1 s after the stick stops"): a linear program over the
stop's jerk profile, on the linear model of the K70M's hanging grapple, against the time-optimal
undamped stop and the ZV-shaped one on the same model. Needs numpy and scipy (Debian's
python3-scipy).

  tools/sway_bound.py [--jerk 4] [--acceleration 1] [--deceleration 2]

The model: the tip moves along a line at v0 with the grapple hanging still, then stops; the swing
x (rad) obeys x'' + 2 zeta w x' + w^2 x = -(w^2 / g) a, a the tip's acceleration (the K70M's
compound pendulum: the rotator and grapple, 180 kg at 0.7 m, inertia 6.5 kg m^2, the load at
0.95 m, the link's brake 40 N m s/rad; dynamics/pendulum.hpp). The stop's jerk is free within
+-J, its acceleration within [-D, A], its velocity within [0, v0] (the tip never reverses and
never speeds up past the stick), and it comes to rest at most 1 s later than the undamped stop
(issue 28's bound). The LP minimises the largest swing from 1 s after the release on, the swing
left at rest included. Every figure is of this model, not of the simulator, whose tip follows
the reference through the valves' lag.
"""
import argparse
import math

import numpy as np
import scipy.linalg
import scipy.optimize

G = 9.81
DT = 0.01
HORIZON_S = 4.0


def pendulum(load_kg, grapple_kg=180.0, com_m=0.7, inertia=6.5, load_m=0.95, damping=40.0):
    i_pivot = grapple_kg * com_m ** 2 + inertia + load_kg * load_m ** 2
    k = G * (grapple_kg * com_m + load_kg * load_m)
    w = math.sqrt(k / i_pivot)
    return w, damping / (2.0 * i_pivot * w)


def discrete(w, zeta):
    # state: tip velocity, tip acceleration, swing, swing rate; input: jerk (held over DT).
    a = np.array([[0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1], [0, -(w * w / G), -w * w, -2 * zeta * w]])
    b = np.array([[0], [1], [0], [0]])
    m = scipy.linalg.expm(np.block([[a, b], [np.zeros((1, 5))]]) * DT)
    return m[:4, :4], m[:4, 4]


def undamped_stop(v0, jerk, decel):
    ramp = min(decel / jerk, math.sqrt(v0 / jerk))
    cruise = max(0.0, (v0 - jerk * ramp * ramp) / (jerk * ramp))
    n, c = round(ramp / DT), round(cruise / DT)
    return [-jerk] * n + [0.0] * c + [jerk] * n


def zv_stop(v0, jerk, decel, w, zeta):
    raw = np.array(undamped_stop(v0, jerk, decel))
    td = math.pi / (w * math.sqrt(1 - zeta * zeta))
    k = math.exp(-zeta * math.pi / math.sqrt(1 - zeta * zeta))
    shift = round(td / DT)
    out = np.zeros(len(raw) + shift)
    out[: len(raw)] += raw / (1 + k)
    out[shift:] += k * raw / (1 + k)
    return list(out)


def simulate(ad, bd, jerks, v0, n):
    x = np.array([v0, 0.0, 0.0, 0.0])
    states = [x]
    for k in range(n):
        x = ad @ x + bd * (jerks[k] if k < len(jerks) else 0.0)
        states.append(x)
    return np.array(states)


def from_one_second(states, w):
    t = np.arange(len(states)) * DT
    late = np.abs(states[t >= 1.0, 2]).max()
    end = math.hypot(states[-1, 2], states[-1, 3] / w)  # what swings on once at rest
    return max(late, end)


def least_swing(v0, w, zeta, jerk, accel, decel, rest_by_s):
    ad, bd = discrete(w, zeta)
    n = round(HORIZON_S / DT)
    response = np.zeros((n + 1, 4, n))  # the state's response to each cycle's jerk
    for k in range(1, n + 1):
        response[k] = ad @ response[k - 1]
        response[k][:, k - 1] += bd
    free = simulate(ad, bd, [], v0, n)
    t = np.arange(n + 1) * DT
    a_ub, b_ub, a_eq, b_eq = [], [], [], []

    def row(coeffs, z=0.0):
        return np.append(coeffs, z)

    for k in range(1, n + 1):
        a_ub += [row(-response[k][0]), row(response[k][0])]  # 0 <= v <= v0
        b_ub += [free[k][0], v0 - free[k][0]]
        a_ub += [row(response[k][1]), row(-response[k][1])]  # -D <= a <= A
        b_ub += [accel - free[k][1], decel + free[k][1]]
        if t[k] >= 1.0:  # |swing| <= z
            a_ub += [row(response[k][2], -1.0), row(-response[k][2], -1.0)]
            b_ub += [-free[k][2], free[k][2]]
        if t[k] >= rest_by_s:  # at rest
            a_eq += [row(response[k][0]), row(response[k][1])]
            b_eq += [-free[k][0], -free[k][1]]
    for phase in np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False):  # the amplitude at rest
        c, s = math.cos(phase), math.sin(phase)
        a_ub.append(row(c * response[n][2] + s * response[n][3] / w, -1.0))
        b_ub.append(-(c * free[n][2] + s * free[n][3] / w))
    cost = np.zeros(n + 1)
    cost[-1] = 1.0
    res = scipy.optimize.linprog(cost, A_ub=np.array(a_ub), b_ub=np.array(b_ub),
                                 A_eq=np.array(a_eq), b_eq=np.array(b_eq),
                                 bounds=[(-jerk, jerk)] * n + [(0.0, None)], method="highs")
    return res.x[-1] if res.success else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jerk", type=float, default=4.0, help="scaling.jerk_max, m/s^3")
    ap.add_argument("--acceleration", type=float, default=1.0, help="scaling.acceleration_max")
    ap.add_argument("--deceleration", type=float, default=2.0, help="scaling.deceleration_max")
    args = ap.parse_args()
    j, a, d = args.jerk, args.acceleration, args.deceleration
    print("| load | stop from | undamped, from 1 s | ZV-shaped | least possible | ZV reduction "
          "| least possible reduction |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for load in (0, 400, 800):
        w, zeta = pendulum(load)
        ad, bd = discrete(w, zeta)
        for v0 in (0.3, 0.6, 1.0):
            n = round(HORIZON_S / DT)
            stop = undamped_stop(v0, j, d)
            undamped = from_one_second(simulate(ad, bd, stop, v0, n), w)
            zv = from_one_second(simulate(ad, bd, zv_stop(v0, j, d, w, zeta), v0, n), w)
            best = least_swing(v0, w, zeta, j, a, d, len(stop) * DT + 1.0)
            deg = 180.0 / math.pi
            print(f"| {load} kg | {v0} m/s | {undamped * deg:.2f} deg | {zv * deg:.2f} deg | "
                  f"{best * deg:.2f} deg | {100 * (1 - zv / undamped):.0f} % | "
                  f"{100 * (1 - best / undamped):.0f} % |")


if __name__ == "__main__":
    main()
