"""A plate seen through a camera with lens distortion, rendered apart from the project's generator
(tests/support/scene/calibration_plates): for calibrating and measuring in the plate's plane.

The camera is a pinhole with the Brown distortion model (k1, k2 radial; p1, p2 tangential), as
OpenCV and facet both parameterise it. Each pixel is the mean of S x S points of its area: the
point's distorted image coordinates are undistorted (fixed-point iteration), its ray is cut with
the plate's plane and the plate's pattern read there. (Through a distorting lens the pattern's
edges are curves in the image, so the coverage is sampled, not exact.) The lens blur acts on
those points before they are averaged (a Gaussian through its exact transfer function), then
noise and rounding to 8 bits.

Plate coordinates are millimetres in the plate's plane (z = 0); a pose (R, t) takes them to the
camera's frame (z forward). Image coordinates: the centre of pixel (0,0) at (0,0).
"""
import numpy as np


class Camera:
    def __init__(self, size, fx, fy, cx, cy, k1=0.0, k2=0.0, p1=0.0, p2=0.0):
        self.width, self.height = size
        self.fx, self.fy, self.cx, self.cy = fx, fy, cx, cy
        self.k1, self.k2, self.p1, self.p2 = k1, k2, p1, p2

    def distort(self, x, y):
        r2 = x * x + y * y
        radial = 1 + self.k1 * r2 + self.k2 * r2 * r2
        return (x * radial + 2 * self.p1 * x * y + self.p2 * (r2 + 2 * x * x),
                y * radial + self.p1 * (r2 + 2 * y * y) + 2 * self.p2 * x * y)

    def undistort(self, xd, yd):
        x, y = xd.copy(), yd.copy()
        for _ in range(20):
            r2 = x * x + y * y
            radial = 1 + self.k1 * r2 + self.k2 * r2 * r2
            x = (xd - 2 * self.p1 * x * y - self.p2 * (r2 + 2 * x * x)) / radial
            y = (yd - self.p1 * (r2 + 2 * y * y) - 2 * self.p2 * x * y) / radial
        return x, y

    def project(self, R, t, plate_xy):
        """Image point of a plate point."""
        p = R @ np.array([plate_xy[0], plate_xy[1], 0.0]) + t
        xd, yd = self.distort(p[0] / p[2], p[1] / p[2])
        return self.fx * xd + self.cx, self.fy * yd + self.cy

    def render(self, R, t, pattern, rng, points=4, blur=0.7, noise=1.5):
        """`pattern(x_mm, y_mm)` -> grey of the plate at those points (arrays)."""
        w, h = self.width, self.height
        offsets = -0.5 + (np.arange(points) + 0.5) / points
        U, V = np.meshgrid((np.arange(w)[:, None] + offsets[None, :]).ravel(),
                           (np.arange(h)[:, None] + offsets[None, :]).ravel())
        x, y = self.undistort((U - self.cx) / self.fx, (V - self.cy) / self.fy)
        to_plate = np.linalg.inv(np.column_stack([R[:, 0], R[:, 1], t]))
        q = to_plate @ np.stack([x.ravel(), y.ravel(), np.ones(x.size)])
        grey = pattern((q[0] / q[2]).reshape(U.shape), (q[1] / q[2]).reshape(U.shape))
        sigma = blur * points
        pad = int(6 * sigma) + 2
        padded = np.pad(grey, pad, mode='edge')
        fy = np.fft.fftfreq(padded.shape[0])[:, None]
        fx = np.fft.rfftfreq(padded.shape[1])[None, :]
        transfer = np.exp(-2 * np.pi ** 2 * sigma ** 2 * (fx ** 2 + fy ** 2))
        grey = np.fft.irfft2(np.fft.rfft2(padded) * transfer, s=padded.shape)[pad:-pad, pad:-pad]
        image = grey.reshape(h, points, w, points).mean(axis=(1, 3)) + rng.normal(0, noise, (h, w))
        return np.clip(np.round(image), 0, 255).astype(np.uint8)


def rotation(rx, ry, rz):
    """Rotations about x, then y, then z (radians)."""
    cx, sx, cy, sy, cz, sz = np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry), np.cos(rz), np.sin(rz)
    return (np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
            @ np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
            @ np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]]))


def chessboard(cols, rows, square, dark=30.0, light=220.0, around=120.0):
    """Inner corners cols x rows, the first at the plate's origin; one light square of margin."""
    def pattern(x, y):
        i, j = np.floor(x / square), np.floor(y / square)
        on = (i >= -1) & (i <= cols - 1) & (j >= -1) & (j <= rows - 1)
        margin = (i >= -2) & (i <= cols) & (j >= -2) & (j <= rows)
        return np.where(on & ((i + j) % 2 == 0), dark, np.where(margin, light, around))
    return pattern


def holes(circles, dark=40.0, light=200.0):
    """Dark discs (x_mm, y_mm, radius_mm) on a light plate."""
    def pattern(x, y):
        grey = np.full(x.shape, light)
        for cx, cy, r in circles:
            grey = np.where((x - cx) ** 2 + (y - cy) ** 2 < r * r, dark, grey)
        return grey
    return pattern
