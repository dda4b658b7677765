#!/usr/bin/python3
"""facet's measuring commands on scenes it was not written against: rendered by exact_render.py
(exact pixel coverage, lens or grid blur, noise 2, 8 bits), which shares no code with the
project's scene generator. Each table puts an OpenCV-based baseline beside facet, in the same run,
on the same images.

  /usr/bin/python3 bench/independent_renders/bench_independent_renders.py [--smoke]
      [--facet build/release/service/facet]

Rows, per blur model (lens, grid) and blur sigma:
  - straight edges (`facet edges`): distance of each point from the true line, the points 12 px
    and more from the border apart from those nearer; baseline: Canny pixels moved to the
    parabola's peak of the gradient magnitude along the gradient (the classic subpixel edge);
  - circles (`facet circle`): centre and radius; baseline cv2.HoughCircles (HOUGH_GRADIENT_ALT);
  - caliper pairs across bars of 4 and 8 px (`facet caliper --pairs`): each edge's position and
    the width; baseline: the classic caliper (the rectangle's profile, a Gaussian derivative,
    the parabola through its peak);
  - lines (`facet line`, 200 x 16 px along an edge): angle and the ends' offsets; baseline
    cv2.fitLine (L2) on the Canny pixels in the rectangle;
  - shape poses (`facet model create`, `facet match`): a bracket with a hole, any angle;
    baseline: cv2.matchTemplate (TM_CCOEFF_NORMED) of the template turned to the TRUE angle, the
    peak refined by a parabola in x and y (a baseline told the angle);
  - calibrated measurement (`facet calibrate --plane`, `facet circle --calibration`), full run
    only: a camera drawn at random (focal length, centre, radial and tangential distortion), 14
    views of a chessboard plate and one of it lying in the measuring plane (camera_render.py),
    then holes on that plane measured in millimetres; baseline: OpenCV's textbook pipeline
    (findChessboardCorners, cornerSubPix, calibrateCamera, solvePnP on the plane's view) mapping
    facet's image centres into the plane.
Targets printed are the issues' (edges #18, caliper and line #20) and bench_shape's.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from multiprocessing import Pool

import cv2
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import camera_render  # noqa: E402
import exact_render as render  # noqa: E402

FACET = 'build/release/service/facet'
WORK = tempfile.mkdtemp(prefix='facet-independent-')
DARK, LIGHT, NOISE = 60, 170, 2.0


def facet(*args):
    out = subprocess.run([FACET, *args, '--json'], capture_output=True, text=True)
    try:
        return json.loads(out.stdout)
    except json.JSONDecodeError:
        raise SystemExit(f"facet {' '.join(args)}: no JSON ({out.stderr.strip()})")


def save(image, name):
    path = os.path.join(WORK, name)
    cv2.imwrite(path, image)
    return path


def rms(values):
    values = np.asarray(values, float)
    return float(np.sqrt(np.mean(values ** 2))) if values.size else float('nan')


def half_plane(through, normal, reach=600.0):
    """The polygon of the half-plane on the normal's side of the line through `through`."""
    t = np.array([-normal[1], normal[0]])
    p = np.asarray(through, float)
    return [tuple(p + reach * t), tuple(p + reach * t + reach * normal),
            tuple(p - reach * t + reach * normal), tuple(p - reach * t)]


def scene_jobs(rows, scenes):
    """`scenes` jobs per row: the row's values and a seed of its own, 1000 * row + scene."""
    return [(*row, 1000 * k + i) for k, row in enumerate(rows) for i in range(scenes)]


def by_row(results, key_length):
    """(job, ours, baseline) results gathered per row (the job's first `key_length` values):
    {row: (ours, baselines)}, in the jobs' order."""
    rows = {}
    for job, ours, baseline in results:
        mine, theirs = rows.setdefault(job[:key_length], ([], []))
        mine.append(ours)
        theirs.append(baseline)
    return rows


# ---- straight edges ---------------------------------------------------------------------------

def classic_edge_points(image):
    """Canny pixels moved along the gradient to the peak of a parabola through the magnitude."""
    gx = cv2.Sobel(image, cv2.CV_64F, 1, 0, ksize=3)
    gy = cv2.Sobel(image, cv2.CV_64F, 0, 1, ksize=3)
    mag = np.hypot(gx, gy)
    rows, cols = np.nonzero(cv2.Canny(image, 20, 40, L2gradient=True))
    keep = (rows > 0) & (cols > 0) & (rows < image.shape[0] - 1) & (cols < image.shape[1] - 1)
    rows, cols = rows[keep], cols[keep]
    nx, ny = gx[rows, cols], gy[rows, cols]
    norm = np.hypot(nx, ny)
    nx, ny = nx / norm, ny / norm
    sx, sy = np.rint(nx).astype(int), np.rint(ny).astype(int)  # the neighbour along the gradient
    m0, mp, mm = mag[rows, cols], mag[rows + sy, cols + sx], mag[rows - sy, cols - sx]
    den = mp - 2 * m0 + mm
    off = np.where(den < 0, np.clip(0.5 * (mm - mp) / np.where(den < 0, den, -1), -0.5, 0.5), 0)
    step = np.hypot(sx, sy)
    return np.stack([cols + off * sx, rows + off * sy], axis=1), step


def edge_scene(job):
    model, blur, noise, seed = job
    rng = np.random.default_rng(seed)
    size = 64
    angle = rng.uniform(0, np.pi)
    normal = np.array([np.cos(angle), np.sin(angle)])
    through = np.array([size / 2, size / 2]) + rng.uniform(-0.5, 0.5) * normal
    image = render.render((size, size), render.polygon(half_plane(through, normal)), LIGHT, DARK,
                          blur, model, noise, rng)
    points = np.array([p[:2] for p in facet('edges', '--image', save(image, f'e{seed}.png'))
                       ['points']]).reshape(-1, 2)
    classic, _ = classic_edge_points(image)

    def errors(pts):
        d = (pts - through) @ normal
        border = np.minimum(pts.min(axis=1), (size - 1 - pts).min(axis=1))
        on_edge = np.abs(d) < 2
        return d[on_edge & (border >= 12)], d[on_edge & (border >= 2) & (border < 12)]

    inner, near = errors(points)
    classic_inner, _ = errors(classic)
    return job, inner, near, classic_inner


def edges_table(pool, scenes):
    print(f"\n== straight edges, 64x64, any angle (facet edges); {scenes} scenes per row ==")
    print("model blur noise | facet RMS px: >= 12 px from the border | 2-12 px | classic RMS | "
          "classic / facet | target")
    jobs = scene_jobs([(m, b, n) for m in ('lens', 'grid') for b in (0.5, 0.9, 1.5)
                       for n in (0.0, NOISE)], scenes)
    rows = {}
    for job, inner, near, classic in pool.map(edge_scene, jobs):
        row = rows.setdefault(job[:3], ([], [], []))
        row[0].extend(inner), row[1].extend(near), row[2].extend(classic)
    for (model, blur, noise), (inner, near, classic) in rows.items():
        target = 0.01 if noise == 0 else 0.03
        met = rms(inner) <= target and rms(near) <= target
        print(f"{model:5} {blur:4.1f} {noise:5.1f} | {rms(inner):10.4f} | {rms(near):7.4f} | "
              f"{rms(classic):11.4f} | {rms(classic) / rms(inner):15.1f} | <= {target} px: "
              f"{'met' if met else 'MISSED'}")


# ---- circles ----------------------------------------------------------------------------------

def circle_scene(job):
    model, blur, radius, seed = job
    rng = np.random.default_rng(seed)
    size = int(2 * radius + 40)
    cx, cy = size / 2 + rng.uniform(-1, 1), size / 2 + rng.uniform(-1, 1)
    hole = seed % 2 == 1
    image = render.render((size, size), render.disc(cx, cy, radius), DARK if hole else LIGHT,
                          LIGHT if hole else DARK, blur, model, NOISE, rng)
    path = save(image, f'c{seed}.png')
    j = facet('circle', '--image', path, '--centre', f'{cx + rng.uniform(-1, 1)},{cy + rng.uniform(-1, 1)}',
              '--radius', str(radius))
    ours = (np.hypot(j['x'] - cx, j['y'] - cy), j['radius'] - radius) if 'x' in j else None
    found = cv2.HoughCircles(image, cv2.HOUGH_GRADIENT_ALT, 1.5, size, param1=60, param2=0.8,
                             minRadius=int(radius - 5), maxRadius=int(radius + 5))
    hough = None
    if found is not None:
        x, y, r = found[0][0]
        hough = (np.hypot(x - cx, y - cy), r - radius)
    return job, ours, hough


def circles_table(pool, scenes):
    print(f"\n== circles (facet circle), discs and holes; {scenes} scenes per row ==")
    print("model blur radius | facet centre RMS, radius RMS, failed | HoughCircles ALT centre, "
          "radius, failed | Hough / facet centre | target")
    jobs = scene_jobs([(m, b, r) for m in ('lens', 'grid') for b in (0.7, 1.2)
                       for r in (10, 30, 100)], scenes)
    for (model, blur, radius), (ours, hough) in by_row(pool.map(circle_scene, jobs), 3).items():
        o = np.array([v for v in ours if v is not None]).reshape(-1, 2)
        h = np.array([v for v in hough if v is not None]).reshape(-1, 2)
        met = len(o) == len(ours) and rms(o[:, 0]) <= 0.01 and rms(o[:, 1]) <= 0.01
        print(f"{model:5} {blur:4.1f} {radius:6d} | {rms(o[:, 0]):7.4f} {rms(o[:, 1]):7.4f} "
              f"{len(ours) - len(o):3d} | {rms(h[:, 0]):7.4f} {rms(h[:, 1]):7.4f} "
              f"{len(hough) - len(h):3d} | {rms(h[:, 0]) / rms(o[:, 0]):8.1f} | <= 0.01 px: "
              f"{'met' if met else 'MISSED'}")


# ---- caliper pairs ----------------------------------------------------------------------------

def classic_caliper(image, centre, axis, length=40, width=20, smoothing=1.0):
    """The rectangle's mean profile along `axis` (bilinear), its Gaussian derivative, and the
    parabola through each of the two strongest peaks of opposite sign: positions along the axis."""
    across = np.array([-axis[1], axis[0]])
    s = np.arange(-length / 2, length / 2 + 1e-9, 0.5)
    t = np.arange(-width / 2, width / 2 + 1e-9, 1.0)
    S, T = np.meshgrid(s, t)
    mx = (centre[0] + S * axis[0] + T * across[0]).astype(np.float32)
    my = (centre[1] + S * axis[1] + T * across[1]).astype(np.float32)
    profile = cv2.remap(image.astype(np.float32), mx, my, cv2.INTER_LINEAR).mean(axis=0)
    k = np.arange(-8, 9) * 0.5
    kernel = -k * np.exp(-0.5 * (k / smoothing) ** 2)
    d = np.convolve(profile, kernel[::-1], mode='same')
    positions = []
    for sign in (1, -1):
        i = int(np.argmax(sign * d[2:-2])) + 2
        l, c, r = sign * d[i - 1], sign * d[i], sign * d[i + 1]
        den = l - 2 * c + r
        positions.append(s[i] + (0.5 * (l - r) / den if den < 0 else 0) * 0.5)
    return sorted(positions)


def caliper_scene(job):
    model, blur, width, seed = job
    rng = np.random.default_rng(seed)
    size = 80
    angle = rng.uniform(0, np.pi)
    along = np.array([np.cos(angle), np.sin(angle)])  # the bar's direction
    axis = np.array([-along[1], along[0]])            # the caliper's, across the bar
    centre = np.array([size / 2, size / 2]) + rng.uniform(-1, 1, 2)
    bar = [tuple(centre + 60 * along + width / 2 * axis), tuple(centre - 60 * along + width / 2 * axis),
           tuple(centre - 60 * along - width / 2 * axis), tuple(centre + 60 * along - width / 2 * axis)]
    image = render.render((size, size), render.polygon(bar), LIGHT, DARK, blur, model, NOISE, rng)
    degrees = np.degrees(np.arctan2(-axis[1], axis[0]))  # counter-clockwise on screen
    j = facet('caliper', '--image', save(image, f'k{seed}.png'), '--rect',
              f'{centre[0]},{centre[1]},40,20,{degrees}', '--pairs')
    edges = sorted(e['position'] for e in j.get('edges', []))
    ours = None
    if len(edges) == 2 and len(j.get('pairs', [])) == 1:
        ours = (edges[0] + width / 2, edges[1] - width / 2, j['pairs'][0]['width'] - width)
    c0, c1 = classic_caliper(image, centre, axis)  # the same axis, (cos a, -sin a)
    return job, ours, (c0 + width / 2, c1 - width / 2, c1 - c0 - width)


def issue20_verdict(blur, met, targets):
    """The measuring tools' targets (issue 20) hold at blur 0.9; other rows are for reading."""
    if blur != 0.9:
        return '-'
    return f"{targets}: {'met' if met else 'MISSED'}"


def caliper_table(pool, scenes):
    print(f"\n== caliper pairs across a bar (facet caliper --pairs, 40x20 px), any angle; {scenes} "
          "scenes per row ==")
    print("model blur bar px | facet edge RMS, width RMS, failed | classic edge RMS, width RMS | "
          "classic / facet edge | target (#20, blur 0.9)")
    jobs = scene_jobs([(m, b, w) for m in ('lens', 'grid') for b in (0.9, 1.5) for w in (4, 8)],
                      scenes)
    for (model, blur, width), (ours, classic) in by_row(pool.map(caliper_scene, jobs), 3).items():
        o = np.array([v for v in ours if v is not None]).reshape(-1, 3)
        c = np.array(classic).reshape(-1, 3)
        edge, pair = rms(o[:, :2]), rms(o[:, 2])
        verdict = issue20_verdict(blur, len(o) == len(ours) and edge <= 0.02 and pair <= 0.03,
                                  "edge <= 0.02, width <= 0.03 px")
        print(f"{model:5} {blur:4.1f} {width:6d} | {edge:7.4f} {pair:7.4f} {len(ours) - len(o):3d} | "
              f"{rms(c[:, :2]):7.4f} {rms(c[:, 2]):7.4f} | {rms(c[:, :2]) / edge:7.1f} | {verdict}")


# ---- lines ------------------------------------------------------------------------------------

def line_scene(job):
    model, blur, seed = job
    rng = np.random.default_rng(seed)
    size = 240
    angle = rng.uniform(0, np.pi)
    along = np.array([np.cos(angle), np.sin(angle)])
    normal = np.array([-along[1], along[0]])
    centre = np.array([size / 2, size / 2]) + rng.uniform(-1, 1, 2)
    image = render.render((size, size), render.polygon(half_plane(centre, normal)), LIGHT, DARK,
                          blur, model, NOISE, rng)
    degrees = np.degrees(np.arctan2(-along[1], along[0]))
    j = facet('line', '--image', save(image, f'l{seed}.png'), '--rect',
              f'{centre[0]},{centre[1]},200,16,{degrees}')

    def errors(p1, p2):
        d = p2 - p1
        turn = (np.degrees(np.arctan2(d[1], d[0]) - angle) + 90) % 180 - 90
        # offsets of the fitted line from the true one at +-100 px along it
        k = (p2 - p1) / np.linalg.norm(p2 - p1)
        at = lambda u: p1 + ((centre + u * along - p1) @ k) * k
        return turn, [(at(u) - centre) @ normal for u in (-100, 100)]

    ours = None
    if 'line' in j:
        line = j['line']
        ours = errors(np.array([line['x1'], line['y1']]), np.array([line['x2'], line['y2']]))
    rows, cols = np.nonzero(cv2.Canny(image, 20, 40, L2gradient=True))
    pts = np.stack([cols, rows], axis=1).astype(float)
    rel = pts - centre
    inside = (np.abs(rel @ along) <= 100) & (np.abs(rel @ normal) <= 8)
    vx, vy, x0, y0 = cv2.fitLine(pts[inside].astype(np.float32), cv2.DIST_L2, 0, 0.01, 0.01).ravel()
    p0 = np.array([x0, y0], float)
    classic = errors(p0 - 50 * np.array([vx, vy]), p0 + 50 * np.array([vx, vy]))
    return job, ours, classic


def lines_table(pool, scenes):
    print(f"\n== lines (facet line, 200x16 px along an edge), any angle; {scenes} scenes per row ==")
    print("model blur | facet angle RMS deg, ends RMS px, failed | fitLine angle RMS, ends RMS | "
          "fitLine / facet angle | target (#20, blur 0.9)")
    jobs = scene_jobs([(m, b) for m in ('lens', 'grid') for b in (0.5, 0.9, 1.5)], scenes)
    for (model, blur), (ours, classic) in by_row(pool.map(line_scene, jobs), 2).items():
        o = [v for v in ours if v is not None]
        angle, ends = rms([v[0] for v in o]), rms([e for v in o for e in v[1]])
        c_angle, c_ends = rms([v[0] for v in classic]), rms([e for v in classic for e in v[1]])
        verdict = issue20_verdict(blur, len(o) == len(ours) and angle <= 0.005 and ends <= 0.02,
                                  "angle <= 0.005 deg, ends <= 0.02 px")
        print(f"{model:5} {blur:4.1f} | {angle:8.5f} {ends:7.4f} {len(ours) - len(o):3d} | "
              f"{c_angle:8.5f} {c_ends:7.4f} | {c_angle / angle:6.1f} | {verdict}")


# ---- shape poses ------------------------------------------------------------------------------

BRACKET = [(-90, -60), (75, -60), (75, -15), (15, -15), (15, 68), (-30, 68), (-30, 8), (-90, 8)]
HOLE = [(-70, -45), (-52, -45), (-52, -27), (-70, -27)]


def bracket(x, y, theta):
    c, s = np.cos(theta), np.sin(theta)
    place = lambda poly: [(x + c * u - s * v, y + s * u + c * v) for u, v in poly]
    return render.difference(render.polygon(place(BRACKET)), render.polygon(place(HOLE)))


def ncc_at_angle(image, template, x, y, theta):
    """matchTemplate of the template turned to the true angle; the peak refined by parabolas."""
    h, w = template.shape
    turn = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), -np.degrees(theta), 1.0)
    turned = cv2.warpAffine(template, turn, (w, h), flags=cv2.INTER_CUBIC)
    inner = turned[h // 4:h - h // 4, w // 4:w - w // 4]  # the turned corners hold no part
    score = cv2.matchTemplate(image, inner, cv2.TM_CCOEFF_NORMED)
    _, _, _, (px, py) = cv2.minMaxLoc(score)
    if not (0 < px < score.shape[1] - 1 and 0 < py < score.shape[0] - 1):
        return None
    peak = lambda a, b, c: 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
    fx = px + peak(score[py, px - 1], score[py, px], score[py, px + 1])
    fy = py + peak(score[py - 1, px], score[py, px], score[py + 1, px])
    # inner's pixel (0,0) is the template's (w // 4, h // 4)
    return np.hypot(fx + (w - 1) / 2 - w // 4 - x, fy + (h - 1) / 2 - h // 4 - y)


def shape_scene(job):
    model, blur, seed, model_file, template_file = job
    rng = np.random.default_rng(seed)
    width, height = 480, 360
    x, y = width / 2 + rng.uniform(-60, 60), height / 2 + rng.uniform(-40, 40)
    theta = rng.uniform(-np.pi, np.pi)
    image = render.render((height, width), bracket(x, y, theta), LIGHT, DARK, blur, model, NOISE,
                          rng)
    j = facet('match', '--model', model_file, '--image', save(image, f's{seed}.png'))
    ours = None
    if j.get('matches'):
        m = j['matches'][0]
        # facet's angle turns counter-clockwise on screen: -theta in image axes
        ours = (np.hypot(m['x'] - x, m['y'] - y),
                (m['angle'] + np.degrees(theta) + 180) % 360 - 180)
    ncc = ncc_at_angle(image, cv2.imread(template_file, cv2.IMREAD_GRAYSCALE), x, y, theta)
    return job, ours, ncc


def shapes_table(pool, scenes):
    print(f"\n== shape poses (facet model create, facet match: defaults), 480x360, any angle; "
          f"{scenes} scenes per row ==")
    print("model blur | facet pos RMS px, max, angle RMS deg, found | NCC at the true angle: pos "
          "RMS px | NCC / facet pos | target (bench_shape)")
    jobs = []
    for k, (model, blur) in enumerate((m, b) for m in ('lens', 'grid') for b in (0.6, 1.0)):
        rng = np.random.default_rng(7 + k)
        tw, th = 240, 190  # the template: the part at angle 0, its reference point the centre
        template = render.render((th, tw), bracket((tw - 1) / 2, (th - 1) / 2, 0.0), LIGHT, DARK,
                                 blur, model, NOISE, rng)
        template_file = save(template, f't{k}.png')
        model_file = os.path.join(WORK, f't{k}.fsm')
        facet('model', 'create', '--image', template_file, '--out', model_file)
        jobs += [(model, blur, 1000 * k + i, model_file, template_file) for i in range(scenes)]
    for (model, blur), (ours, ncc) in by_row(pool.map(shape_scene, jobs), 2).items():
        o = np.array([v for v in ours if v is not None]).reshape(-1, 2)
        n = [v for v in ncc if v is not None]
        met = len(o) == len(ours) and rms(o[:, 0]) <= 0.02 and rms(o[:, 1]) <= 0.01
        print(f"{model:5} {blur:4.1f} | {rms(o[:, 0]):7.4f} {o[:, 0].max():7.4f} "
              f"{rms(o[:, 1]):8.4f} {len(o):3d}/{len(ours)} | {rms(n):7.4f} | "
              f"{rms(n) / rms(o[:, 0]):6.1f} | pos <= 0.02 px, angle <= 0.01 deg: "
              f"{'met' if met else 'MISSED'}")


# ---- calibrated measurement ------------------------------------------------------------------

BOARD = (11, 8, 2.0)  # inner corners, square mm


def plate_point(K, dist, R, t, u, v):
    """The plate point (mm) seen at image point (u, v) by OpenCV's calibration."""
    x, y = cv2.undistortPoints(np.array([[[u, v]]], np.float64), K, dist).ravel()
    ray = np.array([x, y, 1.0])
    normal, origin = R[:, 2], t
    p = ray * (normal @ origin) / (normal @ ray)
    return (R.T @ (p - t))[:2]


def opencv_calibration(views, plane):
    cols, rows, square = BOARD
    board = np.zeros((cols * rows, 3), np.float32)
    board[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * square
    criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-4)

    def corners(image):
        ok, c = cv2.findChessboardCorners(image, (cols, rows))
        return cv2.cornerSubPix(image, c, (11, 11), (-1, -1), criteria) if ok else None

    found = [c for c in map(corners, views) if c is not None]
    _, K, dist, _, _ = cv2.calibrateCamera([board] * len(found), found, views[0].shape[::-1],
                                           None, None)
    _, rvec, tvec = cv2.solvePnP(board, corners(plane), K, dist)
    return K, dist, cv2.Rodrigues(rvec)[0], tvec.ravel()


def calibrated_scene(seed):
    rng = np.random.default_rng(seed)
    cols, rows, square = BOARD
    fx, cx, cy = rng.uniform(1500, 2600), 319.5 + rng.uniform(-6, 6), 239.5 + rng.uniform(-6, 6)
    k1, k2 = rng.uniform(-0.12, 0.05), rng.uniform(-0.05, 0.05)
    p1, p2 = rng.uniform(-5e-4, 5e-4), rng.uniform(-5e-4, 5e-4)
    camera = camera_render.Camera((640, 480), fx, fx * (1 + rng.uniform(-1e-3, 1e-3)), cx, cy, k1,
                                  k2, p1, p2)
    pattern = camera_render.chessboard(cols, rows, square)
    middle = np.array([(cols - 1) * square / 2, (rows - 1) * square / 2, 0.0])
    folder = os.path.join(WORK, f'plates{seed}')
    os.makedirs(folder)
    views = []
    for k in range(14):  # tilted up to 26 degrees, spread over the field
        R = camera_render.rotation(*rng.uniform(-0.45, 0.45, 2), rng.uniform(-0.3, 0.3))
        z = camera.fx * 28 / rng.uniform(380, 460)  # the board about 400 px across
        t = np.array([rng.uniform(-0.07, 0.07) * z, rng.uniform(-0.05, 0.05) * z, z]) - R @ middle
        views.append(camera.render(R, t, pattern, rng))
        cv2.imwrite(os.path.join(folder, f'plate_{k:02d}.png'), views[-1])
    R = camera_render.rotation(*rng.uniform(-0.08, 0.08, 2), rng.uniform(-0.5, 0.5))
    z = camera.fx * 28 / 420
    t = np.array([rng.uniform(-2, 2), rng.uniform(-2, 2), z]) - R @ middle
    plane = camera.render(R, t, pattern, rng)
    circles = [(rng.uniform(2, 18), rng.uniform(2, 12), rng.uniform(0.8, 2.0)) for _ in range(4)]
    part = camera.render(R, t, camera_render.holes(circles), rng)
    calibration = os.path.join(WORK, f'calibration{seed}.yaml')
    facet('calibrate', '--images', folder, '--board', f'chessboard:{cols}x{rows}:{square:g}',
          '--plane', save(plane, f'plane{seed}.png'), '--out', calibration)
    K, dist, Rcv, tcv = opencv_calibration(views, plane)
    part_file = save(part, f'part{seed}.png')
    ours, baseline, diameters = [], [], []
    mm_per_px = z / camera.fx
    for cx, cy, r in circles:
        u, v = camera.project(R, t, (cx, cy))
        radius = abs(camera.project(R, t, (cx + r, cy))[0] - u)
        j = facet('circle', '--image', part_file, '--centre', f'{u:.2f},{v:.2f}', '--radius',
                  f'{radius:.2f}', '--calibration', calibration)
        world = j.get('world', {})
        if 'x_mm' not in world or 'x' not in j:
            ours.append(None)
            continue
        ours.append((world['x_mm'] - cx, world['y_mm'] - cy))
        diameters.append(world['diameter_mm'] - 2 * r)
        baseline.append(plate_point(K, dist, Rcv, tcv, j['x'], j['y']) - (cx, cy))
    return seed, ours, baseline, diameters, mm_per_px


def calibrated_table(pool, seeds):
    print(f"\n== calibrated measurement in the plane: {seeds} cameras drawn at random, 4 holes each "
          "(facet calibrate, facet circle --calibration) ==")
    print("camera | mm/px | facet centre error RMS um (px), diameter error RMS um, failed | "
          "OpenCV textbook centre error RMS um | OpenCV / facet")
    rows = pool.map(calibrated_scene, range(100, 100 + seeds))
    for seed, ours, baseline, diameters, mm_per_px in rows:
        o = np.array([v for v in ours if v is not None]).reshape(-1, 2)
        centre = rms(np.hypot(o[:, 0], o[:, 1])) * 1000
        base = rms(np.hypot(*np.array(baseline).reshape(-1, 2).T)) * 1000
        print(f"{seed:6d} | {mm_per_px:.4f} | {centre:7.2f} ({centre / 1000 / mm_per_px:.3f}) "
              f"{rms(diameters) * 1000:7.2f} {len(ours) - len(o):3d} | {base:7.2f} | "
              f"{base / centre:6.1f}")


def main():
    global FACET
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--smoke', action='store_true', help='a few scenes per row')
    parser.add_argument('--facet', default=FACET, help='the facet command (default: %(default)s)')
    args = parser.parse_args()
    FACET = args.facet
    if not os.access(FACET, os.X_OK):
        raise SystemExit(f"{FACET}: no facet command there (build first, or pass --facet)")
    scale = 1 if args.smoke else 10
    print("bench_independent_renders: scenes by exact_render.py (exact pixel coverage; lens = "
          "blur before the pixel integrates, grid = blur after), noise 2, 8 bits; errors against "
          "the rendered truth")
    try:
        with Pool(2) as pool:
            edges_table(pool, 2 * scale)
            circles_table(pool, 2 * scale)
            caliper_table(pool, 3 * scale)
            lines_table(pool, 2 * scale)
            shapes_table(pool, 1 * scale if args.smoke else 12)
            if not args.smoke:
                calibrated_table(pool, 4)
    finally:
        shutil.rmtree(WORK, ignore_errors=True)


if __name__ == '__main__':
    main()
