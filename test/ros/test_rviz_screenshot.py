#!/usr/bin/env python3
"""Starts rviz with the shipped config on a virtual X display, takes a screenshot and checks
that every ball of the (paused) scene is drawn at its projected position in its state's colour,
every segment along its projected line, and that no more ball is drawn than there is. The
scene (test/scenes/screenshot.yaml) is stepped a little first, so that it has balls at rest
and balls in flight."""

import math
import os
import sys
import unittest

import rospkg
import rospy
import rostest
import yaml

from ball_physics_sim.msg import BallStateArray
from ball_physics_sim.srv import Step

PACKAGE = rospkg.RosPack().get_path("ball_physics_sim")
sys.path.insert(0, os.path.join(PACKAGE, "scripts"))
import rviz_capture  # noqa: E402  (lives in scripts/, shared with the picture script)

CONFIG = os.path.join(PACKAGE, "config", "sim.rviz")
STEPS_FIRST = 12  # 0.1 s: the balls on the floor are at rest, the others still in flight

# Points sampled inside each ball, as fractions of its radius, clear of the lit rim.
INSIDE_BALL = [(0.0, 0.0), (0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5)]
# The counted ball pixels over the discs' area: the darkest part of the rim is not counted.
BALL_AREA_RATIO = (0.7, 1.1)
# Points checked along each segment, as fractions of its length.
SEGMENT_SAMPLES = (0.1, 0.3, 0.5, 0.7, 0.9)
HIDDEN_MARGIN = 0.1  # m beyond a ball's radius where a segment may still be covered


class RvizScreenshot(unittest.TestCase):
    def test_markers_are_drawn_where_the_balls_and_segments_are(self):
        rospy.init_node("test_rviz_screenshot")
        rospy.wait_for_service("step", timeout=60)
        sim_time = rospy.ServiceProxy("step", Step)(STEPS_FIRST).time
        balls = rviz_capture.Latest("balls", BallStateArray,
                                    lambda m: m.header.stamp).stamped(sim_time).balls
        self.assertTrue(any(b.at_rest for b in balls) and not all(b.at_rest for b in balls),
                        "the scene must show both ball colours; at_rest: %s"
                        % [b.at_rest for b in balls])
        with open(rospy.get_param("/sim/scene_file")) as f:
            segments = yaml.safe_load(f)["segments"]
        view = rviz_capture.TopDownView(CONFIG)
        log_path = os.path.join(rospkg.get_log_dir(), "test_rviz_screenshot_rviz.log")
        with rviz_capture.VirtualDisplay() as display, open(log_path, "w") as log:
            rviz = rviz_capture.start_rviz(display.name, CONFIG, log)
            try:
                rviz_capture.wait_until_drawn(display.name, view, rviz)
                image = rviz_capture.screenshot(display.name)
            finally:
                rviz_capture.stop(rviz)
        shot_path = os.path.join(rospkg.get_log_dir(), "test_rviz_screenshot.png")
        rviz_capture.save_png(image, shot_path)

        area = view.render_area(image)
        problems = []
        for ball in balls:
            expected = rviz_capture.AT_REST if ball.at_rest else rviz_capture.MOVING
            for fx, fy in INSIDE_BALL:
                px, py = view.to_pixel(area, ball.position.x + fx * ball.radius,
                                       ball.position.y + fy * ball.radius)
                if not rviz_capture.is_colour(image.pixel(px, py), expected,
                                              rviz_capture.DARKEST_SPHERE_PIXEL):
                    problems.append("ball %d at (%.2f, %.2f): pixel (%d, %d) is %s, not %s" % (
                        ball.id, ball.position.x, ball.position.y, px, py,
                        image.pixel(px, py), "at-rest blue" if ball.at_rest else "moving orange"))
        for i, segment in enumerate(segments):
            along = [(segment["start"][0] + t * (segment["end"][0] - segment["start"][0]),
                      segment["start"][1] + t * (segment["end"][1] - segment["start"][1]))
                     for t in SEGMENT_SAMPLES]
            # A ball resting on a segment hides it.
            visible = [(x, y) for x, y in along if not any(
                math.hypot(x - b.position.x, y - b.position.y) < b.radius + HIDDEN_MARGIN
                for b in balls)]
            self.assertTrue(visible, "every sample of segment %d is under a ball" % (i + 1))
            for x, y in visible:
                px, py = view.to_pixel(area, x, y)
                # Thin segments are two pixels wide: look one pixel around the projection.
                near = [image.pixel(px + dx, py + dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)]
                if not any(rviz_capture.is_segment_colour(p) for p in near):
                    problems.append("segment %d: no segment grey around pixel (%d, %d) at (%.2f, "
                                    "%.2f), found %s" % (i + 1, px, py, x, y, near[4]))
        disc_pixels = sum(math.pi * (b.radius * view.scale) ** 2 for b in balls)
        drawn = sum(rviz_capture.pixels_where(image, area, rviz_capture.is_ball_colour))
        ratio = drawn / disc_pixels
        rospy.loginfo("ball-coloured pixels / the balls' disc area: %.3f", ratio)
        if not BALL_AREA_RATIO[0] <= ratio <= BALL_AREA_RATIO[1]:
            problems.append("ball-coloured pixels cover %.2f of the balls' discs, not within %s"
                            % (ratio, BALL_AREA_RATIO))
        self.assertEqual(problems, [], "screenshot: %s; render area %s" % (shot_path, area))


if __name__ == "__main__":
    rostest.rosrun("ball_physics_sim", "rviz_screenshot", RvizScreenshot)
