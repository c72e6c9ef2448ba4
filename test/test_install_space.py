#!/usr/bin/env python3
"""The install space alone runs the package. scripts/test.sh runs this after `catkin_make install`
in an environment where nothing but the install space's setup.bash is sourced: the package, its
messages and its reconfigure module must come from there, and `roslaunch ball_physics_sim
sim.launch` (its own master on a free port, no rviz) must answer `fire`, `set_ball_state`,
`load_scene` and `~set_parameters`.

Usage: test_install_space.py --install-space DIR [--gtest_output=xml:FILE]   (exits 1 on a failure)
"""
import argparse
import os
import pathlib
import signal
import socket
import subprocess
import sys
import time
import unittest

import rosunit

INSTALL_SPACE = None  # set from the command line


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def inside_install_space(path):
    return pathlib.Path(path).resolve().is_relative_to(INSTALL_SPACE)


class InstallSpace(unittest.TestCase):
    # A failure here is kept for each test to report: rosunit's JUnit file would hold no case for
    # it, and the summary counts cases.
    startup_error = None

    @classmethod
    def setUpClass(cls):
        port = free_port()
        os.environ["ROS_MASTER_URI"] = f"http://127.0.0.1:{port}"
        log_dir = pathlib.Path(os.environ.get("ROS_HOME", "/tmp"))
        log_dir.mkdir(parents=True, exist_ok=True)
        cls.log = open(log_dir / "install_space_launch.log", "w")
        cls.launch = subprocess.Popen(
            ["roslaunch", "-p", str(port), "ball_physics_sim", "sim.launch"],
            stdout=cls.log, stderr=subprocess.STDOUT)
        import rosgraph  # (imported once ROS_MASTER_URI is set)
        import rospy
        deadline = time.monotonic() + 60.0
        while not rosgraph.Master("/test_install_space").is_online():
            if time.monotonic() > deadline or cls.launch.poll() is not None:
                cls.startup_error = f"roslaunch started no master on port {port}"
                return
            time.sleep(0.2)
        rospy.init_node("test_install_space", anonymous=True)
        try:
            rospy.wait_for_service("/fire", timeout=max(1.0, deadline - time.monotonic()))
        except rospy.ROSException as error:
            cls.startup_error = f"sim.launch did not offer /fire: {error}"

    def setUp(self):
        self.assertIsNone(self.startup_error, "see install_space_launch.log")

    @classmethod
    def tearDownClass(cls):
        cls.launch.send_signal(signal.SIGINT)
        try:
            cls.launch.wait(timeout=30)
        except subprocess.TimeoutExpired:
            cls.launch.kill()
            cls.launch.wait()
        cls.log.close()

    def test_the_package_messages_and_reconfigure_module_are_the_install_spaces(self):
        import rospkg
        import ball_physics_sim.srv
        from ball_physics_sim.cfg import SimulatorNodeConfig
        self.assertTrue(inside_install_space(rospkg.RosPack().get_path("ball_physics_sim")))
        self.assertTrue(inside_install_space(ball_physics_sim.srv.__file__))
        self.assertTrue(inside_install_space(SimulatorNodeConfig.__file__))
        self.assertIn("gravity_y", SimulatorNodeConfig.defaults)

    def test_fire_set_ball_state_load_scene_and_set_parameters_answer(self):
        import rospy
        import dynamic_reconfigure.client
        from std_srvs.srv import SetBool
        from ball_physics_sim.msg import BallStateArray
        from ball_physics_sim.srv import Fire, LoadScene, SetBallState

        self.assertTrue(rospy.ServiceProxy("/pause", SetBool)(data=True).success)
        fired = rospy.ServiceProxy("/fire", Fire)()
        self.assertTrue(fired.success, fired.message)
        self.assertGreater(fired.ball_id, 0)
        balls = rospy.wait_for_message("/balls", BallStateArray, timeout=10.0)
        ball = next(b for b in balls.balls if b.id == fired.ball_id)
        stopped = rospy.ServiceProxy("/set_ball_state", SetBallState)(
            ball_id=fired.ball_id, position=ball.position)
        self.assertTrue(stopped.success, stopped.message)
        loaded = rospy.ServiceProxy("/load_scene", LoadScene)(name="wall")  # an installed scene
        self.assertTrue(loaded.success, loaded.message)
        config = dynamic_reconfigure.client.Client("/sim_node", timeout=10.0).update_configuration(
            {"gravity_y": -1.62})
        self.assertEqual(config["gravity_y"], -1.62)


def main():
    global INSTALL_SPACE
    parser = argparse.ArgumentParser()
    parser.add_argument("--install-space", required=True, type=pathlib.Path)
    args, rest = parser.parse_known_args()
    INSTALL_SPACE = args.install_space.resolve()
    rosunit.unitrun("ball_physics_sim", "install_space", InstallSpace, [sys.argv[0]] + rest)


if __name__ == "__main__":
    main()
