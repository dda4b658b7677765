#!/usr/bin/python3
"""How far the references of tests/data/photos' SIFT cases lie from dense alignments.

For each case whose reference began as a SIFT + RANSAC similarity, the template is aligned to the scene
by OpenCV's ECC (cv2.findTransformECC: every pixel of the template, not keypoints), started at
the reference pose, as a Euclidean motion and as an affine one, with three pre-smoothings. It
prints where each puts the template centre, and its distance from the reference. The spread of
these positions is a floor under what the case can tell about a matcher's precision.

    /usr/bin/python3 tests/data/photos/check_reference_ecc.py [case ...]
"""
import math
import os
import sys

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def cases():
    with open(os.path.join(HERE, "cases.txt")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            w = line.split()
            name, templ, scene, count = w[0], w[1], w[2], int(w[4])
            refs = [tuple(map(float, w[5 + 4 * i:9 + 4 * i])) for i in range(count)]
            yield name, templ, scene, refs, w[-1]


def warp_of(pose, centre):
    """Template -> scene map of pose (x, y, angle deg, scale): q = t + s R(a) (p - centre),
    angles counter-clockwise on screen."""
    x, y, a, s = pose
    c, n = math.cos(math.radians(a)), math.sin(math.radians(a))
    m = s * np.array([[c, n], [-n, c]])
    t = np.array([x, y]) - m @ centre
    return np.hstack([m, t[:, None]]).astype(np.float32)


def main(names):
    for name, templ, scene, refs, method in cases():
        if method != "sift" or len(refs) != 1 or (names and name not in names):
            continue
        t = cv2.imread(os.path.join(HERE, templ), cv2.IMREAD_GRAYSCALE).astype(np.float32)
        s = cv2.imread(os.path.join(HERE, scene), cv2.IMREAD_GRAYSCALE).astype(np.float32)
        centre = np.array([(t.shape[1] - 1) / 2, (t.shape[0] - 1) / 2])
        ref = refs[0]
        print(f"{name}: reference {ref[0]:.3f} {ref[1]:.3f}, angle {ref[2]:.3f} deg, scale "
              f"{ref[3]:.4f}")
        for motion, label in ((cv2.MOTION_EUCLIDEAN, "euclidean"), (cv2.MOTION_AFFINE, "affine")):
            for smoothing in (1, 3, 5):
                warp = warp_of(ref, centre)
                try:
                    cc, warp = cv2.findTransformECC(
                        t, s, warp, motion,
                        (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 500, 1e-8), None,
                        smoothing)
                except cv2.error:
                    print(f"  ECC {label:9s} smoothing {smoothing}: did not converge")
                    continue
                q = warp[:, :2] @ centre + warp[:, 2]
                d = math.hypot(q[0] - ref[0], q[1] - ref[1])
                # The similarity nearest the affine map: angle of its rotation part, mean scale.
                angle = math.degrees(math.atan2(warp[0, 1] - warp[1, 0], warp[0, 0] + warp[1, 1]))
                scale = math.sqrt(abs(np.linalg.det(warp[:, :2])))
                print(f"  ECC {label:9s} smoothing {smoothing}: correlation {cc:.4f}  centre "
                      f"{q[0]:.3f} {q[1]:.3f}, {d:.3f} px from the reference; angle {angle:.3f} "
                      f"deg, scale {scale:.4f}")


if __name__ == "__main__":
    main(sys.argv[1:])
