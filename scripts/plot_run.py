#!/usr/bin/env python3
"""Plots a recorded run: the /balls messages of a bag (`rosbag record /balls`, or the bags
scripts/make_pictures.py records) next to the scene file they were run on.

  plot_run.py path BAG SCENE OUT.png     the scene's first ball, thrown from a level floor at its
                                         start height and bouncing on it elastically (the throw
                                         scene), against its exact parabola
  plot_run.py energy BAG SCENE OUT.png   relative change of the kinetic energy (billiards)
  plot_run.py overlap BAG SCENE OUT.png  the largest overlap of a ball with a ball or a segment,
                                         over its radius (pile)
"""

import argparse
import math

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import rosbag  # noqa: E402
import yaml  # noqa: E402


ZERO_ON_LOG_AXIS = 1e-17  # where a zero is drawn on a log axis
# The engine's own bounds, drawn as lines: off its exact path, and overlap over a radius.
PATH_TOLERANCE = 1e-9  # m
OVERLAP_TOLERANCE = 1e-6


def read_states(bag_path):
    """(sim time, balls) of every BallStateArray in the bag, in order."""
    with rosbag.Bag(bag_path) as bag:
        return [(m.header.stamp.to_sec(), m.balls) for _, m, _ in bag.read_messages()
                if m._type == "ball_physics_sim/BallStateArray"]


def plot_path(states, scene, ax_path, ax_error):
    """With no horizontal force and elastic bounces on a level floor, x fixes the time of
    flight: t = (x - x0) / vx, and y repeats the same parabola every 2 vy / g."""
    first = scene["balls"][0]
    (x0, y0), (vx, vy) = first["position"], first["velocity"]
    g = -scene["gravity"][1]
    period = 2.0 * vy / g

    def exact_y(x):
        tau = math.fmod((x - x0) / vx, period)
        return y0 + vy * tau - 0.5 * g * tau * tau

    xs = [balls[0].position.x for _, balls in states]
    ys = [balls[0].position.y for _, balls in states]
    fine = [x0 + (xs[-1] - x0) * i / 2000 for i in range(2001)]
    ax_path.plot(fine, [exact_y(x) for x in fine], color="0.6", lw=3, label="exact parabola")
    ax_path.plot(xs, ys, ".", ms=2, color="tab:orange", label="sim_node, every 1/60 s")
    ax_path.set(xlabel="x (m)", ylabel="y (m)", ylim=(0.0, 1.35 * max(ys)),
                title="A thrown ball bouncing elastically")
    ax_path.legend(loc="upper center", ncol=2)
    times = [t for t, _ in states]
    errors = [abs(y - exact_y(x)) for x, y in zip(xs, ys)]
    ax_error.semilogy(times, [max(e, ZERO_ON_LOG_AXIS) for e in errors], ".", ms=2,
                      color="tab:orange")
    ax_error.axhline(PATH_TOLERANCE, color="tab:red", lw=1, label="%g m" % PATH_TOLERANCE)
    ax_error.set_ylim(bottom=0.1 * ZERO_ON_LOG_AXIS)  # the top follows the data
    ax_error.set(xlabel="sim time (s)", ylabel="|y - exact y| (m)",
                 title="Distance from the exact parabola (0 drawn at %g)" % ZERO_ON_LOG_AXIS)
    ax_error.legend(loc="upper right")


def kinetic_energy(balls):
    return sum(0.5 * b.mass * (b.velocity.x ** 2 + b.velocity.y ** 2) for b in balls)


def plot_energy(states, ax):
    e0 = kinetic_energy(states[0][1])
    ax.plot([t for t, _ in states], [kinetic_energy(b) / e0 - 1.0 for _, b in states],
            color="tab:blue")
    ax.set(xlabel="sim time (s)", ylabel="E / E0 - 1",
           title="Elastic billiards, %d balls: kinetic energy" % len(states[0][1]))
    ax.ticklabel_format(axis="y", style="sci", scilimits=(0, 0))


def segment_overlap(ball, segment):
    """How far the ball reaches into the segment (its capsule), m; negative when apart."""
    (ax, ay), (bx, by) = segment["start"], segment["end"]
    px, py = ball.position.x, ball.position.y
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy)))
    distance = math.hypot(px - ax - t * dx, py - ay - t * dy)
    return ball.radius + 0.5 * segment.get("thickness", 0.0) - distance


def largest_overlap(balls, segments):
    """The largest overlap over the overlapping ball's radius (the smaller one's for two)."""
    worst = 0.0
    for i, a in enumerate(balls):
        for b in balls[i + 1:]:
            d = math.hypot(a.position.x - b.position.x, a.position.y - b.position.y)
            worst = max(worst, (a.radius + b.radius - d) / min(a.radius, b.radius))
        for s in segments:
            worst = max(worst, segment_overlap(a, s) / a.radius)
    return worst


def plot_overlap(states, scene, ax):
    overlaps = [largest_overlap(b, scene["segments"]) for _, b in states]
    ax.semilogy([t for t, _ in states], [max(o, ZERO_ON_LOG_AXIS) for o in overlaps],
                color="tab:blue", label="largest overlap")
    ax.axhline(OVERLAP_TOLERANCE, color="tab:red", lw=1,
               label="%g of a radius" % OVERLAP_TOLERANCE)
    ax.set_ylim(bottom=0.1 * ZERO_ON_LOG_AXIS)  # the top follows the data
    ax.set(xlabel="sim time (s)", ylabel="overlap / radius",
           title="A pile of %d balls: largest overlap (none drawn at %g)"
           % (len(states[0][1]), ZERO_ON_LOG_AXIS))
    ax.legend(loc="upper right")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kind", choices=("path", "energy", "overlap"))
    parser.add_argument("bag")
    parser.add_argument("scene")
    parser.add_argument("out")
    args = parser.parse_args()
    states = read_states(args.bag)
    if not states:
        parser.error(args.bag + ": no ball_physics_sim/BallStateArray message")
    with open(args.scene) as f:
        scene = yaml.safe_load(f)
    if args.kind == "path":
        fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6.5))
        plot_path(states, scene, top, bottom)
    else:
        fig, ax = plt.subplots(figsize=(7, 3.5))
        if args.kind == "energy":
            plot_energy(states, ax)
        else:
            plot_overlap(states, scene, ax)
    fig.tight_layout()
    fig.savefig(args.out, dpi=90)


if __name__ == "__main__":
    main()
