"""A tiny W3C WebDriver client for Debian's headless Chromium through chromedriver.

Only the standard library: urllib speaks to chromedriver on 127.0.0.1, and nothing is
downloaded. Shared by the browser tests of this folder.
"""
import base64
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

# Debian's packages; the environment may point elsewhere (e.g. to check the skip path).
CHROMIUM = os.environ.get('FACET_CHROMIUM', '/usr/bin/chromium')
CHROMEDRIVER = os.environ.get('FACET_CHROMEDRIVER', '/usr/bin/chromedriver')
ELEMENT_KEY = 'element-6066-11e4-a52e-4f735466cecf'  # the W3C element reference key


def skip_or_fail_without_chromium():
    """Returns when Chromium and chromedriver exist. Otherwise fails the test with a clear message,
    or, with FACET_SKIP_BROWSER=1, says that it skipped and exits with CTest's skip code 77."""
    missing = [p for p in (CHROMIUM, CHROMEDRIVER) if not os.access(p, os.X_OK)]
    if not missing:
        return
    message = ('browser test needs ' + ' and '.join(missing) +
               ' (Debian packages chromium and chromium-driver; deploy/install-deps.sh installs them)')
    if os.environ.get('FACET_SKIP_BROWSER') == '1':
        print('SKIPPED: ' + message + '; FACET_SKIP_BROWSER=1 is set', flush=True)
        sys.exit(77)
    print('FAILED: ' + message + '. Set FACET_SKIP_BROWSER=1 to skip the browser tests.', flush=True)
    sys.exit(1)


def free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def http(method, url, body=None, headers=None, timeout=30):
    """(status, parsed JSON or bytes) for one request; HTTP errors are answers, not exceptions."""
    data = None if body is None else json.dumps(body).encode()
    request = urllib.request.Request(url, data=data, method=method, headers=headers or {})
    if data is not None:
        request.add_header('Content-Type', 'application/json')
    try:
        with urllib.request.urlopen(request, timeout=timeout) as response:
            status, raw = response.status, response.read()
    except urllib.error.HTTPError as e:
        status, raw = e.code, e.read()
    try:
        return status, json.loads(raw)
    except ValueError:
        return status, raw


class Browser:
    """One chromedriver process with one headless Chromium session."""

    def __init__(self, width=1280, height=1000):
        self.profile = tempfile.mkdtemp(prefix='facet-chromium-')
        self.port = free_port()
        self.log = open(os.path.join(self.profile, 'chromedriver.log'), 'w')
        self.driver = subprocess.Popen([CHROMEDRIVER, '--port=%d' % self.port],
                                       stdout=self.log, stderr=subprocess.STDOUT)
        self.base = 'http://127.0.0.1:%d' % self.port
        deadline = time.time() + 20
        while True:
            try:
                status, body = http('GET', self.base + '/status', timeout=2)
                if status == 200 and body['value'].get('ready'):
                    break
            except (OSError, ValueError):
                pass
            if time.time() > deadline or self.driver.poll() is not None:
                raise RuntimeError('chromedriver did not become ready')
            time.sleep(0.1)
        args = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
                '--disable-component-update', '--disable-sync', '--no-first-run',
                '--disable-dev-shm-usage', '--hide-scrollbars',
                '--user-data-dir=' + os.path.join(self.profile, 'user-data'),
                '--window-size=%d,%d' % (width, height)]
        status, body = http('POST', self.base + '/session', {'capabilities': {'alwaysMatch': {
            'browserName': 'chrome',
            'goog:chromeOptions': {'binary': CHROMIUM, 'args': args},
            'goog:loggingPrefs': {'browser': 'ALL'},
        }}}, timeout=60)
        if status != 200:
            self.close()
            raise RuntimeError('cannot start Chromium: %s' % body)
        self.session = self.base + '/session/' + body['value']['sessionId']

    def _call(self, method, path, body=None):
        status, answer = http(method, self.session + path, body)
        if status != 200:
            raise RuntimeError('%s %s: %s %s' % (method, path, status, answer))
        return answer['value']

    def open(self, url):
        self._call('POST', '/url', {'url': url})

    def run(self, script, *args):
        return self._call('POST', '/execute/sync', {'script': script, 'args': list(args)})

    def run_async(self, script, *args):
        """`script` gets its callback as the last argument."""
        return self._call('POST', '/execute/async', {'script': script, 'args': list(args)})

    def wait_for(self, script, timeout=20, what='condition'):
        deadline = time.time() + timeout
        while time.time() < deadline:
            value = self.run(script)
            if value:
                return value
            time.sleep(0.1)
        raise AssertionError('timed out after %g s waiting for %s' % (timeout, what))

    def element(self, css):
        return self._call('POST', '/element', {'using': 'css selector', 'value': css})[ELEMENT_KEY]

    def rect(self, css):
        r = self._call('GET', '/element/%s/rect' % self.element(css))
        return int(r['x']), int(r['y']), int(r['width']), int(r['height'])

    def click(self, css):
        self._call('POST', '/element/%s/click' % self.element(css), {})

    def alert_text(self):
        return self._call('GET', '/alert/text')

    def answer_prompt(self, text):
        self._call('POST', '/alert/text', {'text': text})
        self._call('POST', '/alert/accept', {})

    def screenshot(self, path):
        png = base64.b64decode(self._call('GET', '/screenshot'))
        with open(path, 'wb') as f:
            f.write(png)
        return path

    def console(self):
        """Browser console entries since the last call: [{'level', 'message', ...}]."""
        for path in ('/se/log', '/log'):
            status, answer = http('POST', self.session + path, {'type': 'browser'})
            if status == 200:
                return answer['value']
        raise RuntimeError('chromedriver gives no browser log')

    def close(self):
        if hasattr(self, 'session'):
            http('DELETE', self.session)
        self.driver.terminate()
        try:
            self.driver.wait(10)
        except subprocess.TimeoutExpired:
            self.driver.kill()
        self.log.close()
        shutil.rmtree(self.profile, ignore_errors=True)


def region_spread(png_path, rect, scale=1.0):
    """Standard deviation of the grey values inside rect (x, y, w, h in CSS pixels) of a
    screenshot: about 0 for a blank region, large where something is drawn."""
    import cv2  # python3-opencv; imported here so the skip path needs nothing but the stdlib
    image = cv2.imread(png_path, cv2.IMREAD_GRAYSCALE)
    x, y, w, h = (int(round(v * scale)) for v in rect)
    crop = image[y:y + h, x:x + w]
    if crop.size == 0:
        raise AssertionError('region %s lies outside the %dx%d screenshot' %
                             (rect, image.shape[1], image.shape[0]))
    return float(crop.std())
