#!/usr/bin/env python3
"""Starts rviz with the shipped config on a virtual X display, takes a screenshot and checks
that every ball of the (paused) default scene is drawn at its projected position in its state's
colour, every segment along its projected line, and that no more ball is drawn than there is."""

import math
import os
import sys
import time
import unittest

import rospkg
import rospy
import rostest
import yaml

from ball_physics_sim.msg import BallStateArray

PACKAGE = rospkg.RosPack().get_path("ball_physics_sim")
sys.path.insert(0, os.path.join(PACKAGE, "scripts"))
import rviz_capture  # noqa: E402  (lives in scripts/, shared with the picture script)

CONFIG = os.path.join(PACKAGE, "config", "sim.rviz")
SCENE = os.path.join(PACKAGE, "config", "scenes", "default.yaml")

# The colours src/markers.cpp gives, 0..1.
MOVING = (1.0, 0.55, 0.1)
AT_REST = (0.35, 0.45, 0.8)
SEGMENT = (0.85, 0.85, 0.85)

# rviz lights a sphere by the cosine of the light's incidence: a sphere's pixels keep its
# colour's direction in RGB and get darker toward the rim. Within this cosine a pixel is taken
# for the colour; the background and the other markers' colours are all further off.
SAME_HUE_COSINE = 0.995
DARKEST_SPHERE_PIXEL = 0.3  # of the colour's full brightness
# Points sampled inside each ball, as fractions of its radius, clear of the lit rim.
INSIDE_BALL = [(0.0, 0.0), (0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5)]
# The counted ball pixels over the discs' area: the darkest part of the rim is not counted.
BALL_AREA_RATIO = (0.7, 1.1)
# Points checked along each segment, as fractions of its length.
SEGMENT_SAMPLES = (0.1, 0.3, 0.5, 0.7, 0.9)
HIDDEN_MARGIN = 0.1  # m beyond a ball's radius where a segment may still be covered
# rviz takes ~30 s to start with software GL on 2 cores; slower while other tests run.
RVIZ_START_TIMEOUT = 240.0  # s
SETTLE = 3.0  # s after the first ball pixel, so that every marker of the array is drawn


def is_colour(pixel, colour, darkest, brightest=1.0):
    p = [c / 255.0 for c in pixel]
    norm_p = math.sqrt(sum(c * c for c in p))
    norm_c = math.sqrt(sum(c * c for c in colour))
    if not darkest * norm_c <= norm_p <= brightest * norm_c + 1e-9:
        return False
    return sum(a * b for a, b in zip(p, colour)) >= SAME_HUE_COSINE * norm_p * norm_c


def is_ball_colour(pixel):
    return any(is_colour(pixel, c, DARKEST_SPHERE_PIXEL) for c in (MOVING, AT_REST))


def ball_pixels(image, area):
    left, top, right, bottom = area
    return (1 for y in range(top, bottom) for x in range(left, right)
            if is_ball_colour(image.pixel(x, y)))


class RvizScreenshot(unittest.TestCase):
    def test_markers_are_drawn_where_the_balls_and_segments_are(self):
        rospy.init_node("test_rviz_screenshot")
        balls = rospy.wait_for_message("balls", BallStateArray, timeout=60).balls
        with open(SCENE) as f:
            segments = yaml.safe_load(f)["segments"]
        view = rviz_capture.TopDownView(CONFIG)
        log_path = os.path.join(rospkg.get_log_dir(), "test_rviz_screenshot_rviz.log")
        with rviz_capture.VirtualDisplay() as display, open(log_path, "w") as log:
            rviz = rviz_capture.start_rviz(display.name, CONFIG, log)
            try:
                self.wait_for_markers(display, view, rviz, log_path)
                time.sleep(SETTLE)
                image = rviz_capture.screenshot(display.name)
            finally:
                rviz_capture.stop(rviz)
        shot_path = os.path.join(rospkg.get_log_dir(), "test_rviz_screenshot.png")
        rviz_capture.save_png(image, shot_path)

        area = view.render_area(image)
        problems = []
        for ball in balls:
            expected = AT_REST if ball.at_rest else MOVING
            for fx, fy in INSIDE_BALL:
                px, py = view.to_pixel(area, ball.position.x + fx * ball.radius,
                                       ball.position.y + fy * ball.radius)
                if not is_colour(image.pixel(px, py), expected, DARKEST_SPHERE_PIXEL):
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
                if not any(is_colour(p, SEGMENT, 0.95, 1.05) for p in near):
                    problems.append("segment %d: no segment grey around pixel (%d, %d) at (%.2f, "
                                    "%.2f), found %s" % (i + 1, px, py, x, y, near[4]))
        disc_pixels = sum(math.pi * (b.radius * view.scale) ** 2 for b in balls)
        ratio = sum(ball_pixels(image, area)) / disc_pixels
        rospy.loginfo("ball-coloured pixels / the balls' disc area: %.3f", ratio)
        if not BALL_AREA_RATIO[0] <= ratio <= BALL_AREA_RATIO[1]:
            problems.append("ball-coloured pixels cover %.2f of the balls' discs, not within %s"
                            % (ratio, BALL_AREA_RATIO))
        self.assertEqual(problems, [], "screenshot: %s; render area %s" % (shot_path, area))

    def wait_for_markers(self, display, view, rviz, log_path):
        """Until a screenshot's render area shows a ball-coloured pixel."""
        deadline = time.time() + RVIZ_START_TIMEOUT
        while time.time() < deadline:
            if rviz.poll() is not None:
                self.fail("rviz exited with %d; its output: %s" % (rviz.returncode, log_path))
            image = rviz_capture.screenshot(display.name)
            area = view.render_area(image)
            if area and any(ball_pixels(image, area)):
                return
            time.sleep(2.0)
        self.fail("no ball drawn within %.0f s; rviz output: %s" % (RVIZ_START_TIMEOUT, log_path))


if __name__ == "__main__":
    rostest.rosrun("ball_physics_sim", "rviz_screenshot", RvizScreenshot)
