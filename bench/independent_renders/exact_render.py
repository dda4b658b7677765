"""Scenes rendered apart from facet's own generator (tests/support/scene), for measuring facet on
images it was not written against.

Shapes are filled discs and simple polygons on a uniform background. Each pixel holds the exact
share of its area the shape covers: for a disc from the closed-form area of a disc cut by a
quarter-plane, for a polygon by clipping it to the pixel square. Two blur models:
  - "lens": the Gaussian acts before the pixel integrates. The coverage is computed on cells
    S times smaller than a pixel, blurred there through the Gaussian's exact transfer function
    (FFT), then averaged over each pixel's S x S cells.
  - "grid": the Gaussian acts on the pixel-integrated image, as a sampled kernel truncated at
    4 sigma and normalised (what a blur filter does).
Then additive Gaussian noise and rounding to 8 bits. With `crop` the scene is rendered on a larger
canvas and the image cut from its middle, so that the scene continues past the image border as a
camera's view does.

Coordinates: x right, y down, the centre of pixel (0,0) at (0,0) (pixel (0,0) covers
[-0.5, 0.5]^2).
"""
import numpy as np


def _quadrant_area(x, y, radius):
    """Area of {X <= x, Y <= y} inside the disc of `radius` about the origin (arrays)."""
    r = radius
    x = np.clip(x, -r, r)

    def antiderivative(u):  # of sqrt(r^2 - u^2)
        return 0.5 * (u * np.sqrt(np.maximum(r * r - u * u, 0.0)) + r * r * np.arcsin(np.clip(u / r, -1, 1)))

    def chord_area(lo, hi):  # integral of sqrt(r^2 - u^2) over [lo, hi], 0 when hi <= lo
        return np.where(hi > lo, antiderivative(np.maximum(hi, lo)) - antiderivative(lo), 0.0)

    upper_half = chord_area(-r, x)  # the half disc above y = 0 left of x
    yc = np.clip(y, -r, r)
    s = np.sqrt(np.maximum(r * r - yc * yc, 0.0))  # where the line Y = y meets the circle
    sign = np.where(y >= 0, 1.0, -1.0)
    # Below Y = y: outside |X| < s the whole chord on y's side, inside it up to y.
    below = (sign * chord_area(-r, np.minimum(x, -s)) + yc * np.clip(np.minimum(x, s) + s, 0, None)
             + sign * chord_area(s, np.maximum(np.minimum(x, r), s)))
    area = upper_half + below
    area = np.where(y >= r, 2 * upper_half, area)
    return np.where(y <= -r, 0.0, area)


def disc_coverage(shape, cx, cy, radius, step=1.0):
    """Share of each cell (size `step`, cell (0,0) centred at 0) inside the disc."""
    h, w = shape
    x0 = np.arange(w) * step - cx - step / 2
    y0 = np.arange(h) * step - cy - step / 2
    X0, Y0 = np.meshgrid(x0, y0)
    X1, Y1 = X0 + step, Y0 + step
    q = lambda x, y: _quadrant_area(x, y, radius)
    return np.clip((q(X1, Y1) - q(X0, Y1) - q(X1, Y0) + q(X0, Y0)) / (step * step), 0.0, 1.0)


def _clipped_area(poly, x0, x1, y0, y1):
    """Area of a polygon clipped to [x0, x1] x [y0, y1] (Sutherland-Hodgman, then the shoelace)."""
    def clip(points, inside, cut):
        out = []
        for i in range(len(points)):
            a, b = points[i], points[(i + 1) % len(points)]
            if inside(a):
                out.append(a)
            if inside(a) != inside(b):
                out.append(cut(a, b))
        return out

    def at_x(v):
        return lambda a, b: (v, a[1] + (b[1] - a[1]) * (v - a[0]) / (b[0] - a[0]))

    def at_y(v):
        return lambda a, b: (a[0] + (b[0] - a[0]) * (v - a[1]) / (b[1] - a[1]), v)

    points = list(poly)
    for inside, cut in ((lambda q: q[0] >= x0, at_x(x0)), (lambda q: q[0] <= x1, at_x(x1)),
                        (lambda q: q[1] >= y0, at_y(y0)), (lambda q: q[1] <= y1, at_y(y1))):
        points = clip(points, inside, cut)
        if not points:
            return 0.0
    twice = sum(points[i][0] * points[(i + 1) % len(points)][1]
                - points[(i + 1) % len(points)][0] * points[i][1] for i in range(len(points)))
    return abs(twice) / 2


def polygon_coverage(shape, poly, step=1.0):
    """Share of each cell (size `step`, cell (0,0) centred at 0) inside a simple polygon: cells an
    edge passes through are clipped exactly, the others decided at their centre."""
    h, w = shape
    poly = np.asarray(poly, float)
    rows, cols = np.mgrid[0:h, 0:w]
    X, Y = cols * step, rows * step
    inside = np.zeros(shape, bool)
    n = len(poly)
    for i in range(n):  # even-odd rule along rows
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % n]
        crosses = (ay > Y) != (by > Y)
        x_at = ax + (Y - ay) * (bx - ax) / np.where(by != ay, by - ay, 1.0)
        inside ^= crosses & (X < x_at)
    coverage = inside.astype(float)
    for i in range(n):
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % n]
        c0 = max(int(np.floor((min(ax, bx) - step) / step)), 0)
        c1 = min(int(np.ceil((max(ax, bx) + step) / step)), w - 1)
        r0 = max(int(np.floor((min(ay, by) - step) / step)), 0)
        r1 = min(int(np.ceil((max(ay, by) + step) / step)), h - 1)
        if c1 < c0 or r1 < r0:
            continue
        rr, cc = np.mgrid[r0:r1 + 1, c0:c1 + 1]
        px, py = cc * step, rr * step
        dx, dy = bx - ax, by - ay
        t = np.clip(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0, 1)
        near = np.hypot(px - ax - t * dx, py - ay - t * dy) <= 0.75 * step  # > half a diagonal
        for r, c in zip(rr[near], cc[near]):
            coverage[r, c] = _clipped_area(poly, c * step - step / 2, c * step + step / 2,
                                           r * step - step / 2, r * step + step / 2) / (step * step)
    return coverage


def _lens_blur(cells, sigma):
    """The continuous Gaussian's transfer function exp(-2 pi^2 sigma^2 f^2) on a grid (FFT), the
    grid's border values repeated beyond it."""
    if sigma <= 0:
        return cells
    h, w = cells.shape
    pad = int(np.ceil(6 * sigma)) + 2
    padded = np.pad(cells, pad, mode='edge')
    fy = np.fft.fftfreq(padded.shape[0])[:, None]
    fx = np.fft.rfftfreq(padded.shape[1])[None, :]
    transfer = np.exp(-2 * np.pi ** 2 * sigma ** 2 * (fx ** 2 + fy ** 2))
    out = np.fft.irfft2(np.fft.rfft2(padded) * transfer, s=padded.shape)
    return out[pad:pad + h, pad:pad + w]


def _grid_blur(image, sigma, truncate=4.0):
    """A sampled, normalised Gaussian kernel, separable, border pixels repeated."""
    r = int(truncate * sigma + 0.5)
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    k /= k.sum()
    p = np.pad(image, r, mode='edge')
    rows = sum(k[i] * p[:, i:i + image.shape[1]] for i in range(2 * r + 1))
    return sum(k[i] * rows[i:i + image.shape[0], :] for i in range(2 * r + 1))


def render(shape, coverage, fg, bg, blur, model, noise, rng, fine=8, crop=True):
    """An 8-bit image (rows, cols) = `shape`. `coverage(shape, step, offset)` gives the shape's
    share of cells of size `step` whose cell (0,0) is centred at `offset` (both axes)."""
    if crop:
        m = int(np.ceil(4 * blur)) + 3
        larger = lambda sh, step, off: coverage(sh, step, off - m)
        image = render((shape[0] + 2 * m, shape[1] + 2 * m), larger, fg, bg, blur, model, noise,
                       rng, fine, crop=False)
        return image[m:m + shape[0], m:m + shape[1]].copy()
    h, w = shape
    if model == 'lens':
        cells = coverage((h * fine, w * fine), 1.0 / fine, -0.5 + 0.5 / fine)
        share = _lens_blur(cells, blur * fine).reshape(h, fine, w, fine).mean(axis=(1, 3))
    elif model == 'grid':
        share = _grid_blur(coverage((h, w), 1.0, 0.0), blur)
    else:
        raise ValueError(f"blur model {model!r}: lens or grid")
    image = bg + (fg - bg) * share + rng.normal(0, noise, share.shape)
    return np.clip(np.round(image), 0, 255).astype(np.uint8)


def disc(cx, cy, radius):
    return lambda shape, step, off: disc_coverage(shape, cx - off, cy - off, radius, step)


def polygon(vertices):
    def coverage(shape, step, off):
        return polygon_coverage(shape, [(x - off, y - off) for x, y in vertices], step)
    return coverage


def difference(outer, inner):
    """A shape with a hole (the hole lies inside the shape)."""
    return lambda shape, step, off: outer(shape, step, off) - inner(shape, step, off)
