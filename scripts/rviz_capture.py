"""rviz on a virtual X display, its screenshots, where the world lands in them, and waiting
for the node's messages of a given sim time.

Shared by the screenshot rostest and the docs' picture script. Needs Xvfb (xvfb) and
ImageMagick's `import`; rviz renders with Mesa's software GL.
"""

import ctypes
import math
import os
import signal
import socket
import subprocess
import time

import rospy
import yaml

SCREEN = "1280x800x24"

# The colours src/markers.cpp gives, 0..1 (a change there must be made here too).
MOVING = (1.0, 0.55, 0.1)
AT_REST = (0.35, 0.45, 0.8)
SEGMENT = (0.85, 0.85, 0.85)

# rviz lights a sphere by the cosine of the light's incidence: a sphere's pixels keep its
# colour's direction in RGB and get darker toward the rim. Within this cosine a pixel is taken
# for the colour; the background and the other markers' colours are all further off.
SAME_HUE_COSINE = 0.995
DARKEST_SPHERE_PIXEL = 0.3  # of the colour's full brightness
# rviz takes 10-30 s to start with software GL on 2 cores; slower while other work runs.
RVIZ_START_TIMEOUT = 240.0  # s
XVFB_START_TIMEOUT = 30.0  # s
SETTLE = 3.0  # s after the first marker pixel, so that every marker of the array is drawn
MESSAGE_TIMEOUT = 60.0  # s for the node to answer or publish


class Latest:
    """The latest message on a topic, and a wait for one stamped at a given sim time."""

    def __init__(self, topic, message_type, stamp_of):
        self.topic, self.stamp_of, self.message = topic, stamp_of, None
        self.subscriber = rospy.Subscriber(topic, message_type, self.received)

    def received(self, message):
        self.message = message

    def stamped(self, sim_time, process=None):
        """Waits for a message stamped `sim_time` (stamps are rounded to nanoseconds). Raises
        RuntimeError if none comes within MESSAGE_TIMEOUT or the node `process`, if given,
        ends."""
        deadline = time.time() + MESSAGE_TIMEOUT
        ended = lambda: process is not None and process.poll() is not None  # noqa: E731
        while time.time() < deadline and not ended():
            message = self.message
            if message is not None and abs(self.stamp_of(message).to_sec() - sim_time) < 1e-6:
                return message
            time.sleep(0.002)
        raise RuntimeError("no %s message stamped %.6f s (node %s)" % (
            self.topic, sim_time, "ended" if ended() else "silent"))


def die_with_parent():
    """Run in a child before exec: the kernel kills it when its parent dies, so that a test
    killed on its time limit leaves no Xvfb or rviz behind."""
    pr_set_pdeathsig = 1
    ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, signal.SIGKILL)


class VirtualDisplay:
    """An Xvfb server on the first free display number (Xvfb picks it and tells us)."""

    def __enter__(self):
        read_end, write_end = os.pipe()
        self.server = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write_end), "-screen", "0", SCREEN, "-nolisten", "tcp"],
            pass_fds=(write_end,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=die_with_parent)
        os.close(write_end)
        with os.fdopen(read_end) as answer:
            number = answer.readline().strip()
        if not number:
            self.server.kill()
            raise RuntimeError("Xvfb did not start (is the xvfb package installed?)")
        self.name = ":" + number
        self._wait_until_it_answers("/tmp/.X11-unix/X" + number)
        return self

    def _wait_until_it_answers(self, socket_path):
        """Returns once a client can connect to the server's socket (its file, or Linux's
        abstract one of the same name): rviz started before that aborts ("could not connect to
        display"). Raises RuntimeError if Xvfb exits first or does not answer within
        XVFB_START_TIMEOUT."""
        deadline = time.time() + XVFB_START_TIMEOUT
        while time.time() < deadline:
            if self.server.poll() is not None:
                raise RuntimeError("Xvfb exited with %d" % self.server.returncode)
            for path in (socket_path, "\0" + socket_path):
                with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as client:
                    try:
                        client.connect(path)
                        return
                    except OSError:
                        pass
            time.sleep(0.05)
        stop(self.server)
        raise RuntimeError("Xvfb did not answer on %s within %.0f s" % (
            socket_path, XVFB_START_TIMEOUT))

    def __exit__(self, *exc):
        stop(self.server)


def stop(process, grace=10.0):
    """SIGTERM, then SIGKILL if it is still there after `grace` seconds."""
    if process.poll() is not None:
        return
    process.send_signal(signal.SIGTERM)
    try:
        process.wait(grace)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def start_rviz(display, config, log):
    """rviz with `config` on `display`; its output goes to the open file `log`."""
    env = dict(os.environ, DISPLAY=display, LIBGL_ALWAYS_SOFTWARE="1")
    return subprocess.Popen(["rviz", "-d", config], env=env, stdout=log, stderr=subprocess.STDOUT,
                            preexec_fn=die_with_parent)


class Image:
    """An RGB picture: pixel(x, y) is an (r, g, b) tuple of 0..255, (0, 0) the top left."""

    def __init__(self, width, height, data):
        self.width, self.height, self.data = width, height, data

    def pixel(self, x, y):
        at = 3 * (y * self.width + x)
        return tuple(self.data[at:at + 3])


def is_colour(pixel, colour, darkest, brightest=1.0):
    """Whether an (r, g, b) pixel shows `colour` lit at between `darkest` and `brightest` of its
    brightness."""
    p = [c / 255.0 for c in pixel]
    norm_p = math.sqrt(sum(c * c for c in p))
    norm_c = math.sqrt(sum(c * c for c in colour))
    if not darkest * norm_c <= norm_p <= brightest * norm_c + 1e-9:
        return False
    return sum(a * b for a, b in zip(p, colour)) >= SAME_HUE_COSINE * norm_p * norm_c


def is_ball_colour(pixel):
    return any(is_colour(pixel, c, DARKEST_SPHERE_PIXEL) for c in (MOVING, AT_REST))


def is_segment_colour(pixel):
    return is_colour(pixel, SEGMENT, 0.95, 1.05)


def pixels_where(image, area, predicate):
    """A 1 for each pixel of `area` (left, top, right, bottom) for which `predicate` holds:
    sum() counts them, any() finds one."""
    left, top, right, bottom = area
    return (1 for y in range(top, bottom) for x in range(left, right)
            if predicate(image.pixel(x, y)))


def wait_until_drawn(display, view, rviz):
    """Returns once rviz's render area shows a ball or a segment and the rest of the markers
    had time to be drawn. Raises RuntimeError if rviz exits or draws neither within
    RVIZ_START_TIMEOUT."""
    deadline = time.time() + RVIZ_START_TIMEOUT
    while time.time() < deadline and not rospy.is_shutdown():
        if rviz.poll() is not None:
            raise RuntimeError("rviz exited with %d" % rviz.returncode)
        image = screenshot(display)
        area = view.render_area(image)
        if area and any(pixels_where(image, area, lambda p: is_ball_colour(p) or
                                     is_segment_colour(p))):
            time.sleep(SETTLE)
            return
        time.sleep(2.0)
    raise RuntimeError("rviz drew no marker within %.0f s, or ROS shut down" % RVIZ_START_TIMEOUT)


def parse_ppm(data):
    """A binary PPM (P6, 8 bits) as an Image."""
    fields, at = [], 0
    while len(fields) < 4:  # magic, width, height, largest value, separated by whitespace
        while data[at:at + 1].isspace():
            at += 1
        start = at
        while not data[at:at + 1].isspace():
            at += 1
        fields.append(data[start:at])
    if fields[0] != b"P6" or fields[3] != b"255":
        raise ValueError("not an 8-bit binary PPM")
    width, height = int(fields[1]), int(fields[2])
    pixels = data[at + 1:at + 1 + 3 * width * height]
    if len(pixels) != 3 * width * height:
        raise ValueError("the PPM is cut short")
    return Image(width, height, pixels)


def screenshot(display):
    """The whole screen of `display`, taken with ImageMagick's import."""
    ppm = subprocess.run(["import", "-display", display, "-window", "root", "-depth", "8", "ppm:-"],
                         check=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE).stdout
    return parse_ppm(ppm)


def save_png(image, path, area=None):
    """Writes `image`, or only its `area` (left, top, right, bottom), as PNG."""
    header = b"P6 %d %d 255\n" % (image.width, image.height)
    crop = []
    if area:
        left, top, right, bottom = area
        crop = ["-crop", "%dx%d+%d+%d" % (right - left, bottom - top, left, top), "+repage"]
    subprocess.run(["convert", "ppm:-"] + crop + [path], input=header + bytes(image.data),
                   check=True)


class TopDownView:
    """The shipped config's view: rviz/TopDownOrtho, `scale` pixels per metre, the focal point
    (x, y) at the centre of the render panel, which is found in a screenshot as the box its
    background colour fills."""

    def __init__(self, config_path):
        with open(config_path) as f:
            config = yaml.safe_load(f)
        manager = config["Visualization Manager"]
        view = manager["Views"]["Current"]
        if view["Class"] != "rviz/TopDownOrtho" or view.get("Angle", 0) != 0:
            raise ValueError(config_path + ": the view must be an unrotated rviz/TopDownOrtho")
        self.scale = float(view["Scale"])
        self.focus = (float(view["X"]), float(view["Y"]))
        self.background = tuple(
            int(c) for c in manager["Global Options"]["Background Color"].split(";"))

    def render_area(self, image):
        """(left, top, right, bottom) of the render panel (right and bottom exclusive), or None
        when no pixel has the background colour yet."""
        xs, ys = [], []
        for y in range(image.height):
            row = image.data[3 * y * image.width:3 * (y + 1) * image.width]
            cols = [x for x in range(image.width) if tuple(row[3 * x:3 * x + 3]) == self.background]
            if cols:
                xs += (cols[0], cols[-1])
                ys.append(y)
        if not ys:
            return None
        return min(xs), ys[0], max(xs) + 1, ys[-1] + 1

    def to_pixel(self, area, x, y):
        """The pixel where world point (x, y) is drawn; y grows downward on the screen."""
        left, top, right, bottom = area
        return (round((left + right) / 2 + (x - self.focus[0]) * self.scale),
                round((top + bottom) / 2 - (y - self.focus[1]) * self.scale))
