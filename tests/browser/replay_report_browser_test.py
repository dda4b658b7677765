"""`facet replay` over a recorded demo folder, and its HTML report in a real headless Chromium.

Runs `facet replay --json` on recipes/demo/bracket_shape with recipe 2, checks the summary
against the folder (one part per image, the sidecars' expected verdicts), then opens the
report from disk: no console errors, one table row per image with every unexpected verdict
highlighted, a thumbnail per failed part that decodes and opens its full picture (labels inside
it and apart), charts for every measured value, and the
histogram and trend of the first one not blank in the screenshot. The screenshot stays in the
output folder.

usage: replay_report_browser_test.py --facet BIN --source REPO --out DIR
"""
import argparse
import base64
import glob
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import overlay_labels  # noqa: E402
import webdriver_client as wd  # noqa: E402


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--facet', required=True)
    parser.add_argument('--source', required=True)
    parser.add_argument('--out', required=True)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    recipes = os.path.join(args.source, 'recipes')
    # Bad input: a clear message naming what is wrong, exit code 1, no report.
    recipe = os.path.join(recipes, 'bracket_shape.recipe.yaml')
    demo = os.path.join(recipes, 'demo', 'bracket_shape')
    bad = os.path.join(args.out, 'bad.html')
    if os.path.exists(bad):
        os.remove(bad)
    for argv, named in (
            (['--recipe', '/nonexistent.yaml', '--images', demo, '--mm-per-pixel', '0.01'],
             '/nonexistent.yaml'),
            (['--recipe', recipe, '--images', '/nonexistent-folder', '--mm-per-pixel', '0.01'],
             '/nonexistent-folder'),
            (['--recipe', recipe, '--images', demo], '--mm-per-pixel'),
            (['--recipe', recipe, '--images', demo, '--mm-per-pixel', '0.01', '--report',
              '/nonexistent-folder/r.html'], '/nonexistent-folder/r.html')):
        if '--report' not in argv:
            argv = argv + ['--report', bad]
        run = subprocess.run([args.facet, 'replay'] + argv, capture_output=True, text=True,
                             timeout=60)
        assert run.returncode == 1 and named in run.stderr, (argv, run.returncode, run.stderr)
    assert not os.path.exists(bad)
    wd.skip_or_fail_without_chromium()
    folder = os.path.join(recipes, 'demo', 'bracket_shape')
    report = os.path.join(args.out, 'replay-report.html')
    run = subprocess.run([args.facet, 'replay', '--recipe',
                          os.path.join(recipes, 'bracket_shape.recipe.yaml'), '--images', folder,
                          '--station', os.path.join(recipes, 'station.yaml'), '--report', report,
                          '--json'], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, 'facet replay failed (%d): %s' % (run.returncode, run.stderr)
    summary = json.loads(run.stdout)
    print('facet replay --json: %s' % run.stdout.strip())
    images = sorted(glob.glob(os.path.join(folder, '*.png')))
    expected = {}
    for image in images:
        with open(image + '.json') as f:
            expected[os.path.basename(image)] = json.load(f)['annotations']['expected_verdict']
    assert summary['images'] == len(images), (summary['images'], len(images))
    assert sum(summary['counts'].values()) == len(images), summary['counts']
    assert summary['recipe']['id'] == 2
    assert summary['capability'], 'no measured value in the summary'

    browser = wd.Browser(width=1300, height=1400)
    try:
        browser.open('file://' + report)
        browser.wait_for('return document.readyState == "complete"', what='the report to load')
        errors = [e for e in browser.console() if e.get('level') == 'SEVERE']
        assert not errors, 'console errors in the report: %s' % errors
        rows = browser.run('return [...document.querySelectorAll("#verdicts tr")].slice(1).map('
                           'r => ({file: r.cells[1].textContent, verdict: r.cells[3].textContent,'
                           ' expected: r.cells[4].firstChild.textContent.trim(),'
                           ' mismatch: r.classList.contains("mismatch")}))')
        assert len(rows) == len(images), (len(rows), len(images))
        mismatches = 0
        for row in rows:
            assert row['expected'] == expected[row['file']], row
            assert row['mismatch'] == (row['verdict'] != row['expected']), row
            mismatches += row['mismatch']
        assert mismatches == summary['unexpected'], (mismatches, summary['unexpected'])
        failed = sum(1 for r in rows if r['verdict'] != 'pass')
        thumbs = browser.run('return [...document.querySelectorAll("img.thumb")]'
                             '.map(i => i.complete && i.naturalWidth > 0)')
        assert len(thumbs) == failed and all(thumbs), (thumbs, failed)
        # Each thumbnail links to its full picture, shown in the page on a click; the labels of
        # that picture lie inside it, clear of the banner and of each other.
        links = browser.run('return [...document.querySelectorAll("img.thumb")]'
                            '.map(i => i.parentElement.getAttribute("href"))')
        assert links and all(h and h.startswith('#full-') for h in links), links
        browser.click('a.enlarge')
        full = browser.wait_for(
            'const f = document.querySelector(".full:target img");'
            'return f && f.complete && f.naturalWidth > 0 && f.getBoundingClientRect().width > 0 '
            '? f.getAttribute("src") : "";', what='the full picture of the first failed part')
        browser.screenshot(os.path.join(args.out, 'replay-report-full-picture.png'))
        png = base64.b64decode(full.split(',', 1)[1])
        boxes = overlay_labels.check_labels_inside(png, 'the first failed part\'s full picture')
        print('full picture: labels inside and apart: %s' % boxes)
        browser.run('window.location.hash = "#failed"')

        charts = browser.run('return document.querySelectorAll(".check").length')
        assert charts == len(summary['capability']), (charts, len(summary['capability']))
        caps = browser.run('return document.querySelectorAll("#capability tr").length - 1')
        assert caps == len(summary['capability']), caps
        print('report: %d rows, %d highlighted mismatches, %d failed-part thumbnails, '
              '%d measured values with charts' % (len(rows), mismatches, len(thumbs), charts))

        browser.screenshot(os.path.join(args.out, 'replay-report-top.png'))
        # Scroll the first charts into view and check they are drawn.
        browser.run('document.querySelector(".check").scrollIntoView()')
        shot = browser.screenshot(os.path.join(args.out, 'replay-report.png'))
        for css in ('.check svg.histogram', '.check svg.trend'):
            # The rect is relative to the document; the screenshot shows the viewport.
            x, y, w, h = browser.rect(css)
            scroll = browser.run('return window.scrollY')
            spread = wd.region_spread(shot, (x, y - scroll, w, h),
                                      browser.run('return window.devicePixelRatio'))
            print('%s: grey-level spread %.1f' % (css, spread))
            assert spread > 8, '%s looks blank (spread %.1f)' % (css, spread)
        browser.run('document.querySelector(".thumbs").scrollIntoView()')
        browser.screenshot(os.path.join(args.out, 'replay-report-thumbnails.png'))
        print('PASSED: report and screenshots in %s' % args.out)
        return 0
    finally:
        browser.close()


if __name__ == '__main__':
    sys.exit(main())
