#!/usr/bin/env python3
"""The client side of scripts/soak.sh: hammers a running sim_node with mixed service calls.

Four threads send a mix of valid and invalid calls (spawn, remove, fire, segments, step), and
a fifth sends aims, one at a time as the node answers them: an aim can take minutes in a big
world (a BANK search in a pile) and would hold every thread that sends one. Together they send
about --rate calls per second (the aims about a sixth), spawning up to the node's ~max_balls.
Every 10 s it writes a CSV row: wall time, sim time, real-time factor over the window, balls,
the node's resident memory, calls answered, refused and unanswered. It ends with the slowest
aim answered and an aim still being answered, which is reported, not waited for. Exits 1 if
the node died, a call failed unanswered or a window's real-time factor fell below
--min-factor.
"""
import argparse
import csv
import math
import os
import random
import sys
import threading
import time

import rospy
from ball_physics_sim.msg import BallStateArray
from ball_physics_sim.srv import (AddSegment, AddSegmentRequest, Aim, AimRequest, Fire,
                                  FireRequest, RemoveBall, RemoveBallRequest, RemoveSegment,
                                  RemoveSegmentRequest, SpawnBall, SpawnBallRequest, Step,
                                  StepRequest)

WINDOW = 10.0  # s of wall time per CSV row
THREADS = 4  # besides the aims' own
AIM_MODES = ["ANGLE", "TARGET", "TARGET_BALLISTIC", "LEAD_BALL", "TIMED", "BANK", "unknown"]


def resident_kib(pid):
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


class Counters:
    def __init__(self):
        self.lock = threading.Lock()
        self.answered = self.refused = self.unanswered = self.client_errors = 0
        self.stop = threading.Event()
        self.ball_ids = []
        self.segment_ids = []
        self.latest_balls = None  # (wall time, sim time, count)
        self.slowest_aim = (0.0, "")  # (wall seconds, mode) of the slowest answered
        self.aim_since = None  # (wall time sent, mode) of an aim not yet answered

    def add(self, answered=0, refused=0, unanswered=0):
        with self.lock:
            self.answered += answered
            self.refused += refused
            self.unanswered += unanswered


def spawn(rng, counters):
    request = SpawnBallRequest()
    request.position.x, request.position.y = rng.uniform(-5.5, 5.5), rng.uniform(0.5, 7.5)
    request.velocity.x, request.velocity.y = rng.uniform(-3, 3), rng.uniform(-3, 3)
    request.radius, request.mass, request.restitution = rng.uniform(0.05, 0.15), 1.0, 0.8
    spoil = rng.randrange(6)
    if spoil == 1:
        request.position.x = math.nan
    elif spoil == 2:
        request.radius = -1.0
    elif spoil == 3:
        request.velocity.x = 1e9
    return "spawn_ball", request


def some_id(rng, counters, kind):
    """Mostly an id of `kind` ("ball_ids", "segment_ids") that exists, else a made-up one."""
    with counters.lock:
        ids = list(getattr(counters, kind))
    return rng.choice(ids) if ids and rng.random() < 0.8 else rng.randrange(1, 10**6)


def remove(rng, counters):
    request = RemoveBallRequest()
    request.ball_id = some_id(rng, counters, "ball_ids")
    return "remove_ball", request


def fire(rng, counters):
    request = FireRequest()
    request.speed = rng.choice([0.0, rng.uniform(1, 20), -1.0, math.inf])
    request.launcher = rng.choice(["", "cannon", "nonexistent"])
    return "fire", request


def aim(rng, counters):
    request = AimRequest()
    request.mode = rng.randrange(7)  # 6 is unknown
    request.target_ball_id = some_id(rng, counters, "ball_ids")  # for LEAD_BALL, TIMED, BANK
    request.angle = rng.choice([rng.uniform(-3, 3), math.nan])
    request.target.x, request.target.y = rng.uniform(-8, 8), rng.uniform(-2, 10)
    request.speed = rng.choice([0.0, rng.uniform(1, 30), -5.0])
    request.high_arc = rng.random() < 0.5
    return "aim", request


def add_segment(rng, counters):
    request = AddSegmentRequest()
    request.start.x, request.start.y = rng.uniform(-5.5, 5.5), rng.uniform(0.5, 7.5)
    request.end.x, request.end.y = request.start.x + rng.uniform(-1, 1), request.start.y + rng.uniform(-1, 1)
    request.thickness = rng.choice([0.0, 0.05, -1.0])
    request.restitution = 0.9
    return "add_segment", request


def remove_segment(rng, counters):
    request = RemoveSegmentRequest()
    request.segment_id = some_id(rng, counters, "segment_ids")
    return "remove_segment", request


def step(rng, counters):
    request = StepRequest()
    request.steps = rng.randrange(0, 3)
    return "step", request  # refused: the simulation runs


# (weight, request maker): spawns and removals dominate, so that the world fills and churns.
# Aims have their own thread, at AIM_WEIGHT of the rate.
CALLS = [(35, spawn), (8, remove), (15, fire), (8, add_segment), (7, remove_segment), (5, step)]
AIM_WEIGHT = 15
TYPES = {"spawn_ball": SpawnBall, "remove_ball": RemoveBall, "fire": Fire, "aim": Aim,
         "add_segment": AddSegment, "remove_segment": RemoveSegment, "step": Step}


def call(proxies, name, request, counters):
    """Sends the call and counts its answer; whether it was answered."""
    try:
        response = proxies[name](request)
    except (rospy.ServiceException, rospy.ROSException):
        counters.add(unanswered=1)
        proxies[name].close()
        proxies[name] = rospy.ServiceProxy(name, TYPES[name], persistent=True)
        return False
    counters.add(answered=1, refused=0 if response.success else 1)
    if not response.success:
        return True
    with counters.lock:
        if name in ("spawn_ball", "fire"):
            counters.ball_ids.append(response.ball_id)
        elif name == "remove_ball" and request.ball_id in counters.ball_ids:
            counters.ball_ids.remove(request.ball_id)  # two threads may remove the same ball
        elif name == "add_segment":
            counters.segment_ids.append(response.segment_id)
        elif name == "remove_segment" and request.segment_id in counters.segment_ids:
            counters.segment_ids.remove(request.segment_id)
    return True


def timed_aim(proxies, name, request, counters):
    """call() for an aim, noting how long its answer took."""
    mode = AIM_MODES[min(request.mode, len(AIM_MODES) - 1)]
    sent = time.monotonic()
    with counters.lock:
        counters.aim_since = (sent, mode)
    answered = False
    try:
        answered = call(proxies, name, request, counters)
    finally:
        with counters.lock:
            counters.aim_since = None
            if answered:
                counters.slowest_aim = max(counters.slowest_aim, (time.monotonic() - sent, mode))


def worker(seed, period, deadline, counters, calls):
    """Sends calls drawn from `calls`, (weight, request maker), one every `period` s."""
    rng = random.Random(seed)
    proxies = {name: rospy.ServiceProxy(name, kind, persistent=True) for name, kind in TYPES.items()}
    makers = [maker for weight, maker in calls for _ in range(weight)]
    next_call = time.monotonic()
    while time.monotonic() < deadline and not counters.stop.is_set() and not rospy.is_shutdown():
        name, request = rng.choice(makers)(rng, counters)
        try:
            (timed_aim if name == "aim" else call)(proxies, name, request, counters)
        except Exception as error:  # a bug of this client, not of the node: counted, reported
            with counters.lock:
                counters.client_errors += 1
            print(f"soak client error: {error!r}", file=sys.stderr)
        # Behind after a slow answer, the thread goes on at its pace rather than in a burst.
        next_call = max(next_call + period, time.monotonic())
        time.sleep(max(0.0, next_call - time.monotonic()))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=600.0)
    parser.add_argument("--rate", type=float, default=300.0, help="calls per second, in all")
    parser.add_argument("--node-pid", type=int, required=True)
    parser.add_argument("--csv", required=True)
    parser.add_argument("--min-factor", type=float, default=0.95,
                        help="the real-time factor every 10 s window must hold")
    args = parser.parse_args()

    rospy.init_node("soak_client", anonymous=True)
    counters = Counters()

    def on_balls(msg):
        with counters.lock:
            counters.latest_balls = (time.monotonic(), msg.header.stamp.to_sec(), len(msg.balls))

    rospy.Subscriber("balls", BallStateArray, on_balls, queue_size=1)
    for name in TYPES:
        rospy.wait_for_service(name, timeout=60.0)
    start = time.monotonic()
    deadline = start + args.seconds
    weights = sum(weight for weight, _ in CALLS) + AIM_WEIGHT
    threads = [threading.Thread(target=worker, daemon=True,
                                args=(seed, THREADS * weights / (args.rate * (weights - AIM_WEIGHT)),
                                      deadline, counters, CALLS))
               for seed in range(THREADS)]
    aims = threading.Thread(target=worker, daemon=True,
                            args=(THREADS, weights / (args.rate * AIM_WEIGHT), deadline, counters,
                                  [(1, aim)]))
    for thread in threads + [aims]:
        thread.start()

    rows = []
    fields = ["wall_s", "sim_s", "real_time_factor", "balls", "rss_kib", "answered",
              "answered_per_s", "refused", "unanswered"]
    previous = None
    alive = True
    with open(args.csv, "w", newline="") as out:
        writer = csv.DictWriter(out, fieldnames=fields)
        writer.writeheader()
        while time.monotonic() + WINDOW <= deadline + 0.5:
            time.sleep(WINDOW)
            alive = os.path.exists(f"/proc/{args.node_pid}")
            with counters.lock:
                latest = counters.latest_balls
                row = {"wall_s": round(time.monotonic() - start, 1), "answered": counters.answered,
                       "refused": counters.refused, "unanswered": counters.unanswered}
            if not alive or latest is None:
                counters.stop.set()
                break
            row.update(sim_s=round(latest[1], 3), balls=latest[2],
                       rss_kib=resident_kib(args.node_pid))
            if previous:
                # No new `balls` message in the window: a step is taking longer than that.
                wall = latest[0] - previous[1][0]
                row["real_time_factor"] = round((latest[1] - previous[1][1]) / wall, 3) if wall else 0.0
                row["answered_per_s"] = round((row["answered"] - previous[0]["answered"]) / WINDOW, 1)
            writer.writerow(row)
            out.flush()
            print(", ".join(f"{k} {row.get(k, '')}" for k in fields), flush=True)
            rows.append(row)
            previous = (row, latest)
    for thread in threads:
        thread.join()
    # An aim still being answered is the node at work, not a call lost: it is reported, not
    # waited for.
    aims.join(timeout=1.0)

    factors = [r["real_time_factor"] for r in rows if "real_time_factor" in r]
    print(f"soak: {args.seconds:.0f} s; calls answered {counters.answered} "
          f"({counters.answered / args.seconds:.0f}/s), refused with a reason {counters.refused}, "
          f"unanswered {counters.unanswered}; node {'alive' if alive else 'DEAD'}; "
          f"client errors {counters.client_errors}")
    if rows:
        print(f"soak: resident memory {rows[0]['rss_kib']} KiB at {rows[0]['wall_s']} s, "
              f"{rows[-1]['rss_kib']} KiB at {rows[-1]['wall_s']} s; balls at the end "
              f"{rows[-1]['balls']}; real-time factor min {min(factors, default=0):.3f}, "
              f"mean {sum(factors) / max(len(factors), 1):.3f}")
    with counters.lock:
        slowest, in_flight = counters.slowest_aim, counters.aim_since
    print(f"soak: slowest aim answered {slowest[0]:.1f} s ({slowest[1] or 'none'})" +
          (f"; a {in_flight[1]} aim unanswered after {time.monotonic() - in_flight[0]:.0f} s"
           if in_flight else ""))
    if not rows:
        print("soak: no ball states arrived", file=sys.stderr)
    slow = [r for r in rows if r.get("real_time_factor", args.min_factor) < args.min_factor]
    for row in slow:
        print(f"soak: real-time factor {row['real_time_factor']} < {args.min_factor} in the window "
              f"ending at {row['wall_s']} s ({row['balls']} balls)", file=sys.stderr)
    ok = (alive and rows and not slow and counters.unanswered == 0 and
          counters.client_errors == 0)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
