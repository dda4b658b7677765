"""Label boxes in an overlay picture, found by their backing colour (service/daemon/overlay.cpp
fills each label's box with BGR (70, 30, 20), a hue a grey camera image never has): for the
browser tests' check that labels lie inside the picture and clear of each other."""

BACKING_BGR = (70, 30, 20)
BANNER_HEIGHT = 22  # pixels per 640 px of picture width (overlay.cpp)


def label_boxes(png_bytes):
    """(boxes, (width, height)): one (x, y, w, h) per connected patch of the backing colour."""
    import cv2  # python3-opencv, python3-numpy
    import numpy as np
    image = cv2.imdecode(np.frombuffer(png_bytes, np.uint8), cv2.IMREAD_COLOR)
    assert image is not None, 'not a PNG picture'
    colour = np.array(BACKING_BGR, np.int16)
    mask = (np.abs(image.astype(np.int16) - colour).max(axis=2) <= 3).astype(np.uint8)
    count, _, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    boxes = [tuple(int(v) for v in stats[i][:4]) for i in range(1, count)
             if stats[i][cv2.CC_STAT_AREA] >= 20]
    return boxes, (image.shape[1], image.shape[0])


def check_labels_inside(png_bytes, what):
    """Asserts every label box lies inside the picture below the banner, cut by no edge, and
    that no two boxes touch; returns the boxes."""
    boxes, (width, height) = label_boxes(png_bytes)
    assert boxes, '%s: no label in the picture' % what
    banner = BANNER_HEIGHT * max(1, width // 640)
    for (x, y, w, h) in boxes:
        assert x > 0 and x + w < width, '%s: label %s cut by a side of the %dx%d picture' % (
            what, (x, y, w, h), width, height)
        assert y >= banner and y + h < height, '%s: label %s under the banner or cut at the ' \
            'bottom of the %dx%d picture' % (what, (x, y, w, h), width, height)
    for i, a in enumerate(boxes):
        for b in boxes[:i]:
            apart = a[0] >= b[0] + b[2] or b[0] >= a[0] + a[2] or a[1] >= b[1] + b[3] or \
                b[1] >= a[1] + a[3]
            assert apart, '%s: labels %s and %s overlap' % (what, a, b)
    return boxes
