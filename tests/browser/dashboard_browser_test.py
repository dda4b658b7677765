"""The live dashboard in a real headless Chromium, against a facetd started here.

facetd replays recipes/demo/bracket_shape in a loop (no PLC) with recipe 2 and a token set. The
test checks: the page loads without console errors; the last image, the trend charts and the
strip are drawn (screenshot regions are not blank); the verdict count rises as new parts are
inspected, without reloading; a change action without the right token is refused (401), in the
page and over plain HTTP; the right token works. Screenshots stay in the output folder.

usage: dashboard_browser_test.py --facetd BIN --source REPO --out DIR
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import overlay_labels  # noqa: E402
import webdriver_client as wd  # noqa: E402

TOKEN = 'browser-test-token-7f3a'


BROKEN_RECIPE = 'broken.recipe.yaml'


def station_config(source, work):
    """recipes/station.yaml with absolute paths, a free HTTP port, the test token and a quick
    looping replay of the bracket_shape demo folder; its recipes folder is a copy with one
    broken recipe added (a problem the page must show)."""
    recipes = os.path.join(work, 'recipes')
    shutil.copytree(os.path.join(source, 'recipes'), recipes)
    open(os.path.join(recipes, BROKEN_RECIPE), 'w').write(
        'schema_version: 1\nid: 99\nname: broken\nsteps:\n  - id: hole\n    kind: circel\n')
    text = open(os.path.join(recipes, 'station.yaml')).read()
    replacements = [
        (r'folder: demo/bracket_registration', 'folder: %s/demo/bracket_shape' % recipes),
        (r'fps: 5', 'fps: 3'),
        (r'trigger: software', 'trigger: free_run'),
        (r'folder: demo/scan_offset', 'folder: %s/demo/scan_offset' % recipes),
        (r'recipes: \.', 'recipes: %s' % recipes),
        (r'database: .*', 'database: %s/results.db' % work),
        (r'folder: /tmp/facet-demo-archive', 'folder: %s/archive' % work),
        (r'port: 8080', 'port: 0'),
        (r'token: .*', 'token: %s' % TOKEN),
        (r'file: calibration.yaml', 'file: %s/calibration.yaml' % recipes),
    ]
    for pattern, value in replacements:
        text, n = re.subn(pattern, value, text, count=1)
        assert n == 1, 'recipes/station.yaml no longer has "%s"' % pattern
    path = os.path.join(work, 'station.yaml')
    open(path, 'w').write(text)
    return path


def start_facetd(facetd, config, work):
    port_file = os.path.join(work, 'http.port')
    log = open(os.path.join(work, 'facetd.log'), 'w')
    # --block-when-behind: every frame is inspected however slow the build (a sanitizer's is
    # slower than the 3 frames/s), so the last picture is always of an inspected part.
    process = subprocess.Popen([facetd, '--config', config, '--recipe', '2', '--no-plc',
                                '--block-when-behind', '--http-port-file', port_file],
                               stdout=log, stderr=subprocess.STDOUT)
    deadline = time.time() + 30
    while not (os.path.exists(port_file) and open(port_file).read().strip()):
        if process.poll() is not None or time.time() > deadline:
            raise AssertionError('facetd did not start:\n' + open(log.name).read())
        time.sleep(0.1)
    return process, 'http://127.0.0.1:%d' % int(open(port_file).read())


def severe(entries):
    return [e for e in entries if e.get('level') == 'SEVERE']


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--facetd', required=True)
    parser.add_argument('--source', required=True)
    parser.add_argument('--out', required=True)
    args = parser.parse_args()
    wd.skip_or_fail_without_chromium()
    os.makedirs(args.out, exist_ok=True)
    work = tempfile.mkdtemp(prefix='facet-dashboard-test-')
    facetd, browser = None, None
    try:
        facetd, base = start_facetd(args.facetd, station_config(args.source, work), work)
        # Wait for the first part so the image exists when the page first asks for it.
        deadline = time.time() + 30
        while not wd.http('GET', base + '/api/summary')[1].get('recent'):
            assert time.time() < deadline, 'facetd inspected no part within 30 s'
            time.sleep(0.2)

        browser = wd.Browser(width=1280, height=1300)
        started = time.time()
        browser.open(base + '/')
        browser.wait_for('return window.facetDashboard && window.facetDashboard.polls > 0 && '
                         'document.getElementById("last-image").complete && '
                         'document.getElementById("last-image").naturalWidth > 0',
                         what='the first data and the last image')
        wall_ms = 1000 * (time.time() - started)
        timing = browser.run(
            'const n = performance.getEntriesByType("navigation")[0];'
            'return {load: n.loadEventEnd, dom: n.domContentLoadedEventEnd,'
            '        firstRender: window.facetDashboard.firstRenderMs};')
        print('page load: domContentLoaded %.0f ms, load event %.0f ms, first data rendered '
              '%.0f ms after navigation start (wall clock to first image: %.0f ms)' %
              (timing['dom'], timing['load'], timing['firstRender'], wall_ms))

        # Let a few polls draw the charts, then look at the page.
        browser.wait_for('return document.querySelectorAll("#charts canvas").length > 0',
                         what='the trend charts')
        time.sleep(1.5)
        errors = severe(browser.console())
        assert not errors, 'console errors while loading the dashboard: %s' % errors
        shot = browser.screenshot(os.path.join(args.out, 'dashboard.png'))
        scale = browser.run('return window.devicePixelRatio')
        regions = {'last image': '#last-image', 'first trend chart': '#charts canvas',
                   'part strip': '#strip'}
        for name, css in regions.items():
            spread = wd.region_spread(shot, browser.rect(css), scale)
            print('%s: grey-level spread %.1f' % (name, spread))
            assert spread > 8, '%s looks blank in the screenshot (spread %.1f)' % (name, spread)
        charts = browser.run('return document.querySelectorAll("#charts canvas").length')
        checks = len(wd.http('GET', base + '/api/summary')[1]['checks'])
        assert charts == checks, '%d trend charts for %d checks' % (charts, checks)
        # Recipe problems are written on the page, not only in a tooltip.
        problems = browser.run(
            'const s = document.getElementById("recipe-problems");'
            'return s.hidden || s.getBoundingClientRect().height === 0 ? "" : s.innerText;')
        print('recipe problems on the page: %r' % problems)
        assert BROKEN_RECIPE in problems and 'circel' in problems, problems

        # The overlay's labels lie inside the picture, clear of the banner and of each other.
        # Every demo part is inspected (pass or fail), and an inspected part's picture labels
        # what it measured. The summary read around the picture names the part it shows.
        before = wd.http('GET', base + '/api/summary')[1]['recent'][-1]
        status, png = wd.http('GET', base + '/api/last.png')
        assert status == 200, status
        after = wd.http('GET', base + '/api/summary')[1]['recent'][-1]
        open(os.path.join(args.out, 'last-overlay.png'), 'wb').write(png)
        shown = 'the picture shows part %s%s: %s' % (
            before['part_id'], '' if before == after else ' or %s' % after['part_id'],
            [{k: p.get(k) for k in ('part_id', 'verdict', 'failed_checks', 'error')}
             for p in ([before] if before == after else [before, after])])
        print(shown)
        for part in (before, after):
            assert part['verdict'] in ('pass', 'fail'), 'a demo part was not inspected: %s\n%s' % (
                shown, open(os.path.join(work, 'facetd.log')).read()[-4000:])
        boxes = overlay_labels.check_labels_inside(png, '/api/last.png (%s)' % shown)
        print('overlay labels inside the picture and apart: %s' % boxes)

        badges = browser.run('return [...document.querySelectorAll("#health .badge")]'
                             '.map(b => b.textContent)')
        print('health badges: %s' % badges)
        assert any(b.startswith('camera connected') for b in badges), badges
        assert 'PLC off' in badges, badges

        # New parts raise the count in place (no reload: the page's poll counter keeps going).
        polls = browser.run('return window.facetDashboard.polls')
        first = int(browser.run('return document.getElementById("count-total").textContent'))
        later = browser.wait_for(
            'const n = +document.getElementById("count-total").textContent;'
            'return n >= %d ? n : 0;' % (first + 3), timeout=20, what='three more parts')
        assert browser.run('return window.facetDashboard.polls') > polls
        server = sum(wd.http('GET', base + '/api/summary')[1]['counts'].values())
        assert first < later <= server, (first, later, server)
        print('verdict count %d -> %d in place (server now %d)' % (first, later, server))
        strip = browser.run('return document.querySelectorAll("#strip .cell.pass, '
                            '#strip .cell.fail, #strip .cell.error").length')
        assert strip == min(50, server) or strip == min(50, later), (strip, later, server)

        # A change without the right token is refused, in the page ...
        browser.click('#action-reset')
        assert 'token' in browser.alert_text().lower()
        browser.answer_prompt('not-the-token')
        message = browser.wait_for('return document.getElementById("action-message").textContent',
                                   what='the answer to the refused action')
        print('page after a wrong token: "%s"' % message)
        assert message == 'refused: wrong token', message
        # ... and over HTTP with no token or a wrong one; the counters stay.
        for headers in ({}, {'Authorization': 'Bearer nope'}):
            for path, body in (('/api/counters/reset', {}), ('/api/recipe', {'id': 1})):
                status, answer = wd.http('POST', base + path, body, headers)
                assert status == 401, (path, headers, status, answer)
        assert sum(wd.http('GET', base + '/api/summary')[1]['counts'].values()) >= later
        # The right token resets the counters, and the page shows it.
        browser.click('#action-reset')
        browser.answer_prompt(TOKEN)
        browser.wait_for('return document.getElementById("action-message").textContent == '
                         '"shift counters reset"', what='the reset to be confirmed')
        shown = int(browser.wait_for(
            'const n = +document.getElementById("count-total").textContent;'
            'return n < %d ? String(n) : "";' % later, what='the count to drop after the reset'))
        print('after reset with the token: count %d' % shown)
        browser.screenshot(os.path.join(args.out, 'dashboard-after-reset.png'))
        print('PASSED: screenshots in %s' % args.out)
        return 0
    finally:
        if browser:
            browser.close()
        if facetd:
            facetd.terminate()
            try:
                facetd.wait(15)
            except subprocess.TimeoutExpired:
                facetd.kill()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == '__main__':
    sys.exit(main())
