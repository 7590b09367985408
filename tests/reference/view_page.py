"""Drives `latvox view`'s page in headless Chromium (Debian's, through Playwright) as a user
would, and writes what it saw for the Rust test to compare with `latvox render`.

    python3 view_page.py URL OUT_DIR --width W --height H --azimuth A --elevation E
        [--section AXIS=MM] [--edit KEY=VALUE] [--save FILE.toml] [--mesh FILE] [--slice FILE]
        [--layer MM] [--fps N] [--shot FILE.png]

Writes OUT_DIR/first.mask and, after the edit, OUT_DIR/edited.mask (one '0'/'1' per pixel, top
row first: where the page's rays met the part), OUT_DIR/first.rgb (the first frame's colours,
8-bit RGB, top row first), OUT_DIR/page.png (a screenshot), and prints one JSON object: frames
drawn, scene versions, whether the edit re-rendered, the saved file, the meshing and slicing
jobs as the page saw them end, the fps, any error the page showed. Exit 3 when no browser can
be started (the test then says so and skips), 1 on any other failure.
"""

import argparse
import base64
import json
import os
import shutil
import sys
import time


def browser_path():
    for p in ("/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"):
        if os.path.exists(p):
            return p
    return shutil.which("chromium")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("url")
    ap.add_argument("out")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--azimuth", type=float, default=45.0)
    ap.add_argument("--elevation", type=float, default=35.26)
    ap.add_argument("--section", default=None, help="AXIS=MM: cut there, keep below")
    ap.add_argument("--edit", default=None)
    ap.add_argument("--save", default=None)
    ap.add_argument("--mesh", default=None, help="mesh the part from the page to this name")
    ap.add_argument("--slice", default=None, help="slice the part from the page to this name")
    ap.add_argument("--layer", type=float, default=0.5, help="the slices' layer, mm")
    ap.add_argument("--fps", type=int, default=0)
    ap.add_argument("--shot", default=None, help="a screenshot of the whole page (PNG)")
    ap.add_argument("--gpu", action="store_true", help="use the machine's GPU, not SwiftShader")
    a = ap.parse_args()

    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        print("no browser: the Python package playwright is not installed", file=sys.stderr)
        sys.exit(3)
    exe = browser_path()
    if exe is None:
        print("no browser: Chromium is not installed", file=sys.stderr)
        sys.exit(3)

    flags = [
        "--no-sandbox", "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--ignore-gpu-blocklist",
    ]
    if a.gpu:
        flags += ["--use-angle=vulkan", "--enable-features=Vulkan", "--enable-gpu"]
    else:
        flags += ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
    out = {}
    with sync_playwright() as p:
        try:
            browser = p.chromium.launch(executable_path=exe, headless=True, args=flags)
        except Exception as e:  # noqa: BLE001 - any failure to start is "no browser"
            print(f"no browser: Chromium did not start: {e}".splitlines()[0], file=sys.stderr)
            sys.exit(3)
        page = browser.new_page(viewport={"width": a.width + 320, "height": a.height + 40})
        errors = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        # The URL latvox printed carries the token in its query: the size joins it.
        sep = "&" if "?" in a.url else "?"
        page.goto(f"{a.url}{sep}width={a.width}&height={a.height}")
        page.wait_for_function("window.latvox && (window.latvox.ready || window.latvox.error)",
                               timeout=120_000)
        err = page.evaluate("window.latvox.error")
        if err:
            print(f"the page failed: {err}", file=sys.stderr)
            sys.exit(1)
        out["renderer"] = page.evaluate(
            "(() => { const g = document.getElementById('view').getContext('webgl2');"
            " const d = g.getExtension('WEBGL_debug_renderer_info');"
            " return d ? g.getParameter(d.UNMASKED_RENDERER_WEBGL) : g.getParameter(g.RENDERER); })()")
        if a.section:
            axis, at = a.section.split("=", 1)
            page.select_option("#sectionAxis", str("xyz".index(axis.strip().lower())))
            page.evaluate("(v) => { const s = document.getElementById('sectionAt');"
                          " s.value = v; s.dispatchEvent(new Event('input')); }", float(at))
        page.evaluate(f"window.latvox.setCamera({{azimuth: {a.azimuth}, elevation: {a.elevation},"
                      " distance: null})")
        out["frames_first"] = page.evaluate("window.latvox.frames")
        with open(os.path.join(a.out, "first.mask"), "w") as f:
            f.write(page.evaluate("window.latvox.mask()"))
        with open(os.path.join(a.out, "first.rgb"), "wb") as f:
            f.write(base64.b64decode(page.evaluate("window.latvox.pixels()")))
        page.locator("#view").screenshot(path=os.path.join(a.out, "page.png"))
        if a.shot:
            page.screenshot(path=a.shot)

        if a.edit:
            key, value = a.edit.split("=", 1)
            version = page.evaluate("window.latvox.version")
            frames = page.evaluate("window.latvox.frames")
            control = page.locator(f"#set-{key}")
            if control.evaluate("e => e.tagName") == "SELECT":
                control.select_option(value)
            else:
                control.fill(value)
                control.dispatch_event("change")
            page.wait_for_function(
                f"window.latvox.version > {version} || window.latvox.error", timeout=120_000)
            err = page.evaluate("window.latvox.error")
            if err:
                print(f"the page refused the edit: {err}", file=sys.stderr)
                sys.exit(1)
            out["rerendered"] = page.evaluate("window.latvox.frames") > frames
            with open(os.path.join(a.out, "edited.mask"), "w") as f:
                f.write(page.evaluate("window.latvox.mask()"))

        if a.save:
            page.fill("#savePath", a.save)
            page.click("#save")
            page.wait_for_function("window.latvox.saved || window.latvox.error", timeout=60_000)
            out["saved"] = page.evaluate("window.latvox.saved")

        # Meshing and slicing as a user asks for them: a name, the button, the job polled to
        # its end by the page.
        for what, name, field in (("meshing", a.mesh, "#meshPath"), ("slicing", a.slice, "#slicePath")):
            if not name:
                continue
            page.fill(field, name)
            if what == "slicing":
                page.fill("#sliceLayer", str(a.layer))
            page.click("#mesh" if what == "meshing" else "#slice")
            page.wait_for_function(
                f"(window.latvox.job && window.latvox.job.what === '{what}'"
                " && !window.latvox.busy) || window.latvox.error", timeout=300_000)
            out[what] = page.evaluate("window.latvox.job")

        if a.fps:
            out["fps"] = page.evaluate(f"window.latvox.bench({a.fps})")

        out["frames"] = page.evaluate("window.latvox.frames")
        out["versions"] = page.evaluate("window.latvox.version")
        out["error"] = page.evaluate("window.latvox.error")
        out["page_errors"] = errors
        browser.close()
    print(json.dumps(out))


if __name__ == "__main__":
    main()
