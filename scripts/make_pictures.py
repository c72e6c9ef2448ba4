#!/usr/bin/env python3
"""Makes the docs' pictures from the real thing: sim_node and rviz (shipped config, the view
fitted to each scene) on a virtual display. Writes to PICTURES_DIR:
  scene_<name>.png  a screenshot of every scene of config/scenes/ (after its `SETTLE_FIRST`)
  interactive_markers.png  the default scene with the handles of rviz's InteractiveMarkers
                    display, which the scenes' screenshots leave out
  shot.gif          the default scene's cannon firing, frames every 1/20 s of sim time
  plot_<kind>.png   the plots of scripts/plot_run.py
and to RECORDINGS_DIR the bags plotted (/balls every 1/60 s of sim time) and a log of the nodes'
output. Run through scripts/pictures.sh, which starts a master.
"""

import argparse
import glob
import os
import subprocess
import sys
import tempfile
import time

import rosbag
import rospy
import yaml
from ball_physics_sim.msg import BallStateArray
from ball_physics_sim.srv import Fire, Step
from visualization_msgs.msg import MarkerArray

import rviz_capture

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(REPO, "config", "scenes")
CONFIG = os.path.join(REPO, "config", "sim.rviz")
TIME_STEP = 1.0 / 120.0  # s, given to the node as ~time_step
# Sim seconds run before a scene's screenshot: piles are shown settled.
SETTLE_FIRST = {"pile": 3.0, "resting": 3.0, "machine": 1.2}
GIF_FRAMES, GIF_STEPS_PER_FRAME = 60, 6  # 3 s of sim time at 20 frames per second
RECORDINGS = {"throw": 10.0, "billiards": 10.0, "pile": 10.0}  # sim seconds of /balls
RECORD_STEPS = 2  # one /balls message per 1/60 s
MARGIN = 0.5  # m of view around a scene's bodies
RENDER_SIZE = (720, 628)  # px, rviz's render panel in the shipped window geometry
RENDER_PERIOD = 1.0 / 30.0  # s, rviz's frame period in the shipped config


def fitted_config(scene, path, handles=False):
    """The shipped rviz config with its top-down view centred on `scene` and scaled to show
    all of its segments, balls and launchers; the interactive markers' display on if
    `handles`."""
    xs, ys = [], []
    for s in scene.get("segments", []):
        xs += [s["start"][0], s["end"][0]]
        ys += [s["start"][1], s["end"][1]]
    for b in scene.get("balls", []):
        r = b["radius"]
        xs += [b["position"][0] - r, b["position"][0] + r]
        ys += [b["position"][1] - r, b["position"][1] + r]
    for launcher in scene.get("launchers", []):
        xs.append(launcher["position"][0])
        ys.append(launcher["position"][1])
    with open(CONFIG) as f:
        config = yaml.safe_load(f)
    for display in config["Visualization Manager"]["Displays"]:
        if display["Class"] == "rviz/InteractiveMarkers":
            display["Enabled"] = display["Value"] = handles
    view = config["Visualization Manager"]["Views"]["Current"]
    view["X"], view["Y"] = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
    view["Scale"] = min(RENDER_SIZE[0] / (max(xs) - min(xs) + 2 * MARGIN),
                        RENDER_SIZE[1] / (max(ys) - min(ys) + 2 * MARGIN))
    with open(path, "w") as f:
        yaml.safe_dump(config, f)


class Node:
    """sim_node on a scene, paused, as a context manager."""

    def __init__(self, scene, log):
        self.args = ["rosrun", "ball_physics_sim", "sim_node", "__name:=sim", "_scene:=" + scene,
                     "_start_paused:=true", "_time_step:=%r" % TIME_STEP]
        self.log = log

    def __enter__(self):
        self.process = subprocess.Popen(self.args, stdout=self.log, stderr=subprocess.STDOUT,
                                        preexec_fn=rviz_capture.die_with_parent)
        try:
            rospy.wait_for_service("step", timeout=rviz_capture.MESSAGE_TIMEOUT)
        except rospy.ROSException:
            rviz_capture.stop(self.process)
            raise
        self.step = rospy.ServiceProxy("step", Step)
        return self

    def __exit__(self, *exc):
        rviz_capture.stop(self.process)
        # The next node advertises the same services: wait until these are gone.
        while True:
            try:
                rospy.wait_for_service("step", timeout=0.2)
                time.sleep(0.2)
            except rospy.ROSException:
                return

    def run_for(self, seconds):
        self.step(round(seconds / TIME_STEP))


def screenshot_scene(name, display, out_dir, log, work, handles=False):
    """scene_<name>.png, or with `handles` interactive_markers.png."""
    scene_file = os.path.join(SCENES, name + ".yaml")
    with open(scene_file) as f:
        scene = yaml.safe_load(f)
    config = os.path.join(work, name + ".rviz")
    fitted_config(scene, config, handles)
    picture = "interactive_markers.png" if handles else "scene_%s.png" % name
    view = rviz_capture.TopDownView(config)
    with Node(name, log) as node:
        if name in SETTLE_FIRST:
            node.run_for(SETTLE_FIRST[name])
        rviz = rviz_capture.start_rviz(display, config, log)
        try:
            rviz_capture.wait_until_drawn(display, view, rviz)
            image = rviz_capture.screenshot(display)
            rviz_capture.save_png(image, os.path.join(out_dir, picture), view.render_area(image))
            if name == "default" and not handles:
                make_gif(node, display, view, out_dir, work)
        finally:
            rviz_capture.stop(rviz)


def markers_stamp(markers):
    # DELETE markers carry no stamp.
    return next(m.header.stamp for m in markers.markers if m.action == m.ADD)


def make_gif(node, display, view, out_dir, work):
    markers = rviz_capture.Latest("markers", MarkerArray, markers_stamp)
    rospy.ServiceProxy("fire", Fire)()
    frames = []
    for i in range(GIF_FRAMES):
        sim_time = node.step(GIF_STEPS_PER_FRAME).time
        markers.stamped(sim_time, node.process)
        time.sleep(3 * RENDER_PERIOD)  # rviz draws what it received at its next frame
        image = rviz_capture.screenshot(display)
        frames.append(os.path.join(work, "frame_%03d.png" % i))
        rviz_capture.save_png(image, frames[-1], view.render_area(image))
    subprocess.run(["convert", "-delay", "5", "-loop", "0"] + frames +
                   ["-resize", "60%", "-layers", "Optimize", os.path.join(out_dir, "shot.gif")],
                   check=True)


def record(name, seconds, out_dir, log):
    """/balls after every RECORD_STEPS steps of `seconds` of sim time, into out_dir/name.bag."""
    with Node(name, log) as node, rosbag.Bag(os.path.join(out_dir, name + ".bag"), "w") as bag:
        balls = rviz_capture.Latest("balls", BallStateArray, lambda m: m.header.stamp)
        for _ in range(round(seconds / (RECORD_STEPS * TIME_STEP))):
            sim_time = node.step(RECORD_STEPS).time
            message = balls.stamped(sim_time, node.process)
            bag.write("balls", message, message.header.stamp)
        balls.subscriber.unregister()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pictures_dir")
    parser.add_argument("recordings_dir")
    args = parser.parse_args()
    pictures, recordings = (os.path.abspath(d) for d in (args.pictures_dir, args.recordings_dir))
    for d in (pictures, recordings):
        os.makedirs(d, exist_ok=True)
    rospy.init_node("make_pictures", disable_signals=True)
    names = sorted(os.path.splitext(os.path.basename(p))[0]
                   for p in glob.glob(os.path.join(SCENES, "*.yaml")))
    with tempfile.TemporaryDirectory() as work, \
            open(os.path.join(recordings, "make_pictures.log"), "w") as log:
        with rviz_capture.VirtualDisplay() as display:
            for name in names:
                print("screenshot of scene", name, flush=True)
                screenshot_scene(name, display.name, pictures, log, work)
            print("screenshot of the handles", flush=True)
            screenshot_scene("default", display.name, pictures, log, work, handles=True)
        for name, seconds in RECORDINGS.items():
            print("recording", seconds, "s of scene", name, flush=True)
            record(name, seconds, recordings, log)
    plot = [sys.executable, os.path.join(REPO, "scripts", "plot_run.py")]
    for kind, name in (("path", "throw"), ("energy", "billiards"), ("overlap", "pile")):
        subprocess.run(plot + [kind, os.path.join(recordings, name + ".bag"),
                               os.path.join(SCENES, name + ".yaml"),
                               os.path.join(pictures, "plot_%s.png" % kind)], check=True)


if __name__ == "__main__":
    main()
