#!/usr/bin/env python3
"""The client side of scripts/rtf.sh.

--write-scene N prints a scene of N balls of radius 0.5 m two diameters apart in a closed box,
no gravity, e = 1, random velocities up to 3 m/s (the benchmark's billiards). Otherwise it
subscribes to `balls` and `markers` for --seconds of wall time, from the first `balls` message
on, and prints the real-time factor (sim time of the last state less the first, over the wall
time between them), each topic's rate and the node's CPU use; exits 1 if no state arrived.
"""
import argparse
import math
import os
import random
import sys
import threading
import time

RADIUS = 0.5
SPEED = 3.0  # m/s, at most


def write_scene(count):
    columns = math.ceil(math.sqrt(count))
    side = 2.0 * columns
    rng = random.Random(1)
    print(f"# Elastic billiards: {count} balls, written by scripts/rtf_client.py.")
    print("name: billiards_rtf")
    print("gravity: [0.0, 0.0]")
    print("segments:")
    corners = [(0.0, 0.0), (side, 0.0), (side, side), (0.0, side)]
    for (ax, ay), (bx, by) in zip(corners, corners[1:] + corners[:1]):
        print(f"  - {{start: [{ax}, {ay}], end: [{bx}, {by}]}}")
    print("balls:")
    for i in range(count):
        speed, angle = rng.uniform(0.0, SPEED), rng.uniform(0.0, 2.0 * math.pi)
        x, y = 2.0 * (i % columns) + 1.0, 2.0 * (i // columns) + 1.0
        print(f"  - {{position: [{x}, {y}], velocity: [{speed * math.cos(angle):.6f}, "
              f"{speed * math.sin(angle):.6f}], radius: {RADIUS}}}")


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def measure(seconds, node_pid):
    import rospy
    from ball_physics_sim.msg import BallStateArray
    from visualization_msgs.msg import MarkerArray

    lock = threading.Lock()
    states = []  # (wall, sim, balls)
    markers = []  # wall
    first = threading.Event()

    def on_balls(msg):
        with lock:
            states.append((time.monotonic(), msg.header.stamp.to_sec(), len(msg.balls)))
        first.set()

    def on_markers(_):
        with lock:
            markers.append(time.monotonic())

    rospy.init_node("rtf_client", anonymous=True, disable_signals=True)
    rospy.Subscriber("balls", BallStateArray, on_balls, queue_size=100)
    rospy.Subscriber("markers", MarkerArray, on_markers, queue_size=100)
    if not first.wait(timeout=120.0):
        print("rtf: no ball states arrived", file=sys.stderr)
        return 1
    cpu_start, wall_start = cpu_seconds(node_pid), time.monotonic()
    time.sleep(seconds)
    cpu = cpu_seconds(node_pid) - cpu_start
    with lock:
        window = [s for s in states if s[0] >= wall_start]
        marker_count = sum(1 for m in markers if m >= wall_start)
    if len(window) < 2 or window[-1][0] == window[0][0]:
        print(f"rtf: {len(window)} ball states in {seconds:.0f} s: the node stalled or died",
              file=sys.stderr)
        return 1
    wall = window[-1][0] - window[0][0]
    print(f"rtf: {window[-1][2]} balls, {seconds:.0f} s of wall time: real-time factor "
          f"{(window[-1][1] - window[0][1]) / wall:.3f} ({window[-1][1] - window[0][1]:.2f} s of "
          f"sim time in {wall:.2f} s), balls {len(window) / seconds:.1f} Hz, markers "
          f"{marker_count / seconds:.1f} Hz, node CPU {100.0 * cpu / seconds:.0f}% of a core")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--write-scene", type=int, metavar="N")
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--node-pid", type=int)
    args = parser.parse_args()
    if args.write_scene is not None:
        if args.write_scene < 1:
            parser.error("--write-scene needs at least one ball")
        write_scene(args.write_scene)
        return 0
    if args.node_pid is None:
        parser.error("--node-pid is needed to measure")
    return measure(args.seconds, args.node_pid)


if __name__ == "__main__":
    sys.exit(main())
