#!/usr/bin/env python3
"""The client side of scripts/rtf.sh.

--write-scene N prints a scene of N balls of radius 0.5 m two diameters apart in a closed box,
no gravity, e = 1, random velocities up to 3 m/s (the benchmark's billiards).

Otherwise it subscribes to `balls` and `markers`, as rviz would, from the first `balls` message
on, for --seconds of wall time. The real-time factor over a stretch of wall time is the sim time
the `balls` stamps gained in it over its length; each topic's rate counts the messages that
arrived in it; the node's CPU use is its user and system time over the stretch. Without --rain
it prints these over the whole stretch. With --rain SCENE_FILE it calls `spawn_ball` 10 times a
second, each time with a ball of radius 0.1 m at rest at a random place in the top metre of the
scene's box (the bounding box of its segments), another place after each refusal for an
overlap, until --balls balls are in the world; it prints the figures of every 10 s window (with
the balls awake at both its ends that did not move at all), the worst window and a verdict
against the target: a real-time factor of at least 0.95, `balls` at 95 % of 60 Hz or more and
no awake ball unmoved in every window, with --balls balls reached. The verdict does not set
the exit status: that is 1 only if no state arrived, the node died or `spawn_ball` refused a
ball for another reason than its place.
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

WINDOW = 10.0  # s of wall time
TARGET_RTF = 0.95
TARGET_BALLS_HZ = 0.95 * 60.0  # the node's default ~publish_rate, less its timing's jitter
DROP_PERIOD = 0.1  # s of wall time between drops
DROP_RADIUS = 0.1  # m
DROP_BAND = 1.0  # m below the top of the box
DROP_TRIES = 50  # places tried for one drop before it is given up
# Each drop is a ball of the default scene's cannon: 1 kg, e = 0.8, no friction.
DROP_MASS = 1.0
DROP_RESTITUTION = 0.8


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
    """The process's user and system time; None once it has died (gone, or a zombie)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
    except FileNotFoundError:
        return None
    if fields[0] in ("Z", "X"):
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class Watch:
    """What arrives on `balls` and `markers`, with the wall time it arrived at."""

    def __init__(self):
        import rospy
        from ball_physics_sim.msg import BallStateArray
        from visualization_msgs.msg import MarkerArray

        self.lock = threading.Lock()
        self.states = []  # (wall, sim, balls)
        self.markers = []  # wall
        self.latest = None  # the last `balls` message
        self.first = threading.Event()
        rospy.Subscriber("balls", BallStateArray, self.on_balls, queue_size=100)
        rospy.Subscriber("markers", MarkerArray, self.on_markers, queue_size=100)

    def on_balls(self, msg):
        with self.lock:
            self.states.append((time.monotonic(), msg.header.stamp.to_sec(), len(msg.balls)))
            self.latest = msg
        self.first.set()

    def on_markers(self, _):
        with self.lock:
            self.markers.append(time.monotonic())

    def figures(self, start, end, node_cpu):
        """The figures of the wall time from start to end; the sim time at an instant is the
        stamp of the last state that had arrived by then, so a stalled node gains none."""
        with self.lock:
            before = [s for s in self.states if s[0] <= start]
            upto = [s for s in self.states if s[0] <= end]
            arrivals = [start] + [s[0] for s in upto if s[0] > start] + [end]
            marker_count = sum(1 for m in self.markers if start < m <= end)
        sim_start = (before or upto or [(0.0, 0.0, 0)])[-1][1]
        last = (upto or [(0.0, sim_start, 0)])[-1]
        wall = end - start
        return {"wall": wall, "sim": last[1] - sim_start, "rtf": (last[1] - sim_start) / wall,
                "balls": last[2], "balls_hz": (len(arrivals) - 2) / wall,
                "markers_hz": marker_count / wall, "cpu": 100.0 * node_cpu / wall,
                "longest_gap": max(b - a for a, b in zip(arrivals, arrivals[1:]))}

    def awake_places(self):
        """{id: (x, y)} of the balls of the last state that are not at rest."""
        with self.lock:
            balls = self.latest.balls if self.latest else []
        return {b.id: (b.position.x, b.position.y) for b in balls if not b.at_rest}


def unmoved(before, after):
    """How many balls awake in both have not moved a bit: an awake ball with nothing to hold
    it up falls, and a still one falls asleep, so these wait while the clock goes on."""
    return sum(1 for i, place in after.items() if before.get(i) == place)


def start_watching():
    """A Watch once the first state has arrived, or None after two minutes without one."""
    import rospy

    rospy.init_node("rtf_client", anonymous=True, disable_signals=True)
    watch = Watch()
    if not watch.first.wait(timeout=120.0):
        print("rtf: no ball states arrived", file=sys.stderr)
        return None
    return watch


def measure(seconds, node_pid):
    watch = start_watching()
    if watch is None:
        return 1
    cpu_start, wall_start = cpu_seconds(node_pid), time.monotonic()
    time.sleep(seconds)
    cpu_end = cpu_seconds(node_pid)
    if cpu_start is None or cpu_end is None:
        print("rtf: sim_node died", file=sys.stderr)
        return 1
    f = watch.figures(wall_start, time.monotonic(), cpu_end - cpu_start)
    print(f"rtf: {f['balls']} balls, {f['wall']:.0f} s of wall time: real-time factor "
          f"{f['rtf']:.3f} ({f['sim']:.2f} s of sim time), balls {f['balls_hz']:.1f} Hz, markers "
          f"{f['markers_hz']:.1f} Hz, node CPU {f['cpu']:.0f}% of a core")
    return 0


def scene_box(scene_file):
    """(x_min, y_min, x_max, y_max) of the scene's segments."""
    import yaml

    with open(scene_file) as text:
        segments = yaml.safe_load(text).get("segments") or []
    xs = [s[end][0] for s in segments for end in ("start", "end")]
    ys = [s[end][1] for s in segments for end in ("start", "end")]
    if not xs:
        raise ValueError(f"{scene_file}: no segments, so no box to rain into")
    return min(xs), min(ys), max(xs), max(ys)


class Rain:
    """Drops a ball into the top of the box every DROP_PERIOD until `target` balls are in the
    world (those the scene starts with included); a slow answer delays the next drop, never
    bunches drops up."""

    def __init__(self, box, target, initial_balls, seed=1):
        self.box, self.target, self.initial_balls = box, target, initial_balls
        self.rng = random.Random(seed)
        self.lock = threading.Lock()
        self.spawned = []  # wall times
        self.refused = []  # wall times: places refused for an overlap
        self.given_up = 0  # drops with no free place in DROP_TRIES
        self.failure = None  # why raining had to stop: not a measurement, a failure
        self.full_at = None  # wall time the target was reached

    def place(self):
        x_min, _, x_max, y_max = self.box
        margin = 2.0 * DROP_RADIUS
        return (self.rng.uniform(x_min + margin, x_max - margin),
                self.rng.uniform(y_max - DROP_BAND, y_max - margin))

    def drop(self, spawn, request):
        """One drop; False once raining must stop."""
        import rospy

        for _ in range(DROP_TRIES):
            request.position.x, request.position.y = self.place()
            try:
                response = spawn(request)
            except (rospy.ServiceException, rospy.ROSException) as error:
                self.failure = f"spawn_ball failed: {error}"
                return False
            with self.lock:
                (self.spawned if response.success else self.refused).append(time.monotonic())
            if response.success:
                return True
            if "would overlap" not in response.message:
                self.failure = f"spawn_ball refused a ball: {response.message}"
                return False
        self.given_up += 1
        return True

    def run(self, deadline):
        try:
            self.fall(deadline)
        except Exception as error:  # a bug of this client: the measurement stops, and says why
            self.failure = f"the rain stopped: {error!r}"

    def fall(self, deadline):
        import rospy
        from ball_physics_sim.srv import SpawnBall, SpawnBallRequest

        spawn = rospy.ServiceProxy("spawn_ball", SpawnBall, persistent=True)
        request = SpawnBallRequest()
        request.radius, request.mass = DROP_RADIUS, DROP_MASS
        request.restitution = DROP_RESTITUTION
        next_drop = time.monotonic()
        while time.monotonic() < deadline:
            if self.initial_balls + len(self.spawned) >= self.target:
                self.full_at = self.spawned[-1] if self.spawned else time.monotonic()
                return
            if not self.drop(spawn, request):
                return
            next_drop = max(next_drop + DROP_PERIOD, time.monotonic())
            time.sleep(max(0.0, next_drop - time.monotonic()))

    def counts(self, start, end):
        with self.lock:
            return (sum(1 for t in self.spawned if start < t <= end),
                    sum(1 for t in self.refused if start < t <= end))


def measure_rain(seconds, node_pid, scene_file, target):
    box = scene_box(scene_file)
    watch = start_watching()
    if watch is None:
        return 1
    load_start = os.getloadavg()
    with watch.lock:
        initial_balls = watch.states[-1][2]
    rain = Rain(box, target, initial_balls)
    wall_start = time.monotonic()
    threading.Thread(target=rain.run, args=(wall_start + seconds,), daemon=True).start()
    print(f"rain: balls of radius {DROP_RADIUS} m every {DROP_PERIOD} s into the top "
          f"{DROP_BAND} m of the box x {box[0]}..{box[2]}, y {box[1]}..{box[3]} of "
          f"{os.path.basename(scene_file)}, {initial_balls} balls there, until {target}; "
          f"load average {load_start[0]:.2f}", flush=True)
    windows = []
    cpu_before, client_before = cpu_seconds(node_pid), time.process_time()
    places_before = watch.awake_places()
    while len(windows) < int(seconds // WINDOW):
        start = wall_start + WINDOW * len(windows)
        time.sleep(max(0.0, start + WINDOW - time.monotonic()))
        cpu_after, client_after = cpu_seconds(node_pid), time.process_time()
        if cpu_before is None or cpu_after is None:
            print("rain: sim_node died", file=sys.stderr)
            return 1
        f = watch.figures(start, start + WINDOW, cpu_after - cpu_before)
        f["spawned"], f["refused"] = rain.counts(start, start + WINDOW)
        f["from"] = start - wall_start
        places_after = watch.awake_places()
        f["unmoved"] = unmoved(places_before, places_after)
        places_before = places_after
        windows.append(f)
        print(f"rain: {f['from']:3.0f}-{f['from'] + WINDOW:<3.0f} s: real-time factor "
              f"{f['rtf']:.3f}, balls {f['balls_hz']:4.1f} Hz (longest gap {f['longest_gap']:.2f} "
              f"s), markers {f['markers_hz']:4.1f} Hz, {f['balls']:4d} balls (+{f['spawned']}, "
              f"{f['refused']} places refused, {f['unmoved']} awake unmoved), node CPU {f['cpu']:3.0f}%, client CPU "
              f"{100.0 * (client_after - client_before) / WINDOW:3.0f}% of a core", flush=True)
        cpu_before, client_before = cpu_after, client_after
        if rain.failure:
            print(f"rain: {rain.failure}", file=sys.stderr)
            return 1
    return verdict(windows, rain, wall_start, target)


def verdict(windows, rain, wall_start, target):
    if not windows:
        print(f"rain: no window of {WINDOW:.0f} s to judge", file=sys.stderr)
        return 1
    worst = min(windows, key=lambda f: f["rtf"])
    slow = sum(1 for f in windows if f["rtf"] < TARGET_RTF)
    sparse = sum(1 for f in windows if f["balls_hz"] < TARGET_BALLS_HZ)
    reached = max(f["balls"] for f in windows)
    frozen = sum(1 for f in windows if f["unmoved"])
    full = (f"{target} balls at {rain.full_at - wall_start:.0f} s" if rain.full_at
            else f"{target} balls not reached")
    print(f"rain: {full}; {len(rain.refused)} places refused, {rain.given_up} drops given up; "
          f"worst window {worst['from']:.0f}-{worst['from'] + WINDOW:.0f} s: real-time factor "
          f"{worst['rtf']:.3f} with {worst['balls']} balls; balls at least "
          f"{min(f['balls_hz'] for f in windows):.1f} Hz; load average {os.getloadavg()[0]:.2f}")
    failures = []
    if slow:
        failures.append(f"real-time factor under {TARGET_RTF} in {slow} of {len(windows)} windows")
    if sparse:
        failures.append(f"balls under {TARGET_BALLS_HZ:.0f} Hz in {sparse} windows")
    if frozen:
        failures.append(f"awake balls that did not move in {frozen} windows: the sim time "
                        f"overstates what was simulated")
    if reached < target:
        failures.append(f"{reached} of {target} balls")
    print(f"rain: {'FAIL: ' + '; '.join(failures) if failures else 'PASS'} (target: real-time "
          f"factor >= {TARGET_RTF} and balls >= {TARGET_BALLS_HZ:.0f} Hz in every {WINDOW:.0f} s "
          f"window, no awake ball unmoved, {target} balls)")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--write-scene", type=int, metavar="N")
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--node-pid", type=int)
    parser.add_argument("--rain", metavar="SCENE_FILE", help="the scene sim_node runs")
    parser.add_argument("--balls", type=int, default=1000, help="with --rain: balls to reach")
    args = parser.parse_args()
    if args.write_scene is not None:
        if args.write_scene < 1:
            parser.error("--write-scene needs at least one ball")
        write_scene(args.write_scene)
        return 0
    if args.node_pid is None:
        parser.error("--node-pid is needed to measure")
    if args.rain:
        if args.seconds < WINDOW:
            parser.error(f"--rain needs at least one window of {WINDOW:.0f} s")
        return measure_rain(args.seconds, args.node_pid, args.rain, args.balls)
    return measure(args.seconds, args.node_pid)


if __name__ == "__main__":
    sys.exit(main())
