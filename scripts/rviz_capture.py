"""rviz on a virtual X display, its screenshots, and where the world lands in them.

Shared by the screenshot rostest and the README picture script. Needs Xvfb (xvfb) and
ImageMagick's `import`; rviz renders with Mesa's software GL.
"""

import os
import signal
import subprocess
import time

import yaml

SCREEN = "1280x800x24"


class VirtualDisplay:
    """An Xvfb server on the first free display number (Xvfb picks it and tells us)."""

    def __enter__(self):
        read_end, write_end = os.pipe()
        self.server = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write_end), "-screen", "0", SCREEN, "-nolisten", "tcp"],
            pass_fds=(write_end,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(write_end)
        with os.fdopen(read_end) as answer:
            number = answer.readline().strip()
        if not number:
            self.server.kill()
            raise RuntimeError("Xvfb did not start (is the xvfb package installed?)")
        self.name = ":" + number
        return self

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
    return subprocess.Popen(["rviz", "-d", config], env=env, stdout=log, stderr=subprocess.STDOUT)


class Image:
    """An RGB picture: pixel(x, y) is an (r, g, b) tuple of 0..255, (0, 0) the top left."""

    def __init__(self, width, height, data):
        self.width, self.height, self.data = width, height, data

    def pixel(self, x, y):
        at = 3 * (y * self.width + x)
        return tuple(self.data[at:at + 3])

    def contains(self, x, y):
        return 0 <= x < self.width and 0 <= y < self.height


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


def save_png(image, path):
    """Writes `image` as PNG (through ImageMagick's convert)."""
    header = b"P6 %d %d 255\n" % (image.width, image.height)
    subprocess.run(["convert", "ppm:-", path], input=header + bytes(image.data), check=True)


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
