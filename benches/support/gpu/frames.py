"""The editor's frame rate without a browser: `latvox view`'s fragment shader (trace.glsl)
drawn through a headless OpenGL context (EGL) with the uniforms and textures the page (view.js)
sets, to time it on a GPU machine that cannot run Chromium.

    python3 frames.py TRACE.glsl SCENE.json... [--frames N] [--out DIR] [--width 800]
        [--height 600] [--azimuth 45] [--elevation 35.26...] [--section NAME:z=25]
        [--check NAME=REF] [--glsl auto|es|330]

Per scene (a `/api/part` answer's "scene", as scenes.py saves them): the fragment shader as
`useVariant` builds it (`#define FILL 0|1` after the version line); the numbers as `loadScene`
sets them (float textures of 1024 RGBA32F texels a line, NEAREST; the box grown by the nudge
for filled parts); the camera as `camera()` (iso: azimuth 45°, elevation atan(1/√2), the page's
default; 30° vertical field, distance 1.04 · half the box's diagonal over sin(half the field));
a section as the page's control sets it (`AXIS=MM` keeps what lies below). Then one warm-up
frame and `--frames` frames back to back, each followed by reading back one pixel (as the
page's `state.bench`): fps = frames / seconds, into an RGBA8 framebuffer (the page's canvas: no
antialiasing) cleared to transparent black. It prints one JSON object (GL renderer and version,
per scene the GLSL dialect used, fps, ms a frame, share of pixels hit, agreement with a
reference) and writes each scene's last frame as OUT/NAME.png (RGBA, top row first; alpha 255
where a ray met the part).

Context: moderngl's standalone EGL context (glcontext, EGL device platform: no display), which
is desktop OpenGL core, not OpenGL ES. The shader is compiled as it is first (`#version 300 es`:
Mesa and NVIDIA accept it through ARB_ES3_compatibility, as seen on llvmpipe and an H200); only
if that fails (or with --glsl 330) is the version line rewritten to `#version 330 core`, keeping
the precision lines (desktop GLSL ignores them). The JSON says which was used.

--check NAME=REF: the share of pixels whose hit (alpha > 127) agrees with REF, a `latvox render
--depth` .npy (finite: hit), a view_page.py .mask ('1': hit) or an RGBA PNG (this script's).
"""

import argparse
import json
import math
import os
import sys
import time

import moderngl
import numpy as np
from PIL import Image

FOV = 30.0  # degrees, vertical, as view.js
VERTEX = "#version 300 es\nin vec2 corner;\nvoid main() { gl_Position = vec4(corner, 0.0, 1.0); }\n"
TEXTURES = ["uStruts", "uPartNodes", "uPartTris", "uKeepNodes", "uKeepTris"]  # units 0..4


def dialect(source, glsl):
    """The source as the page compiles it ('es') or with a desktop version line ('330')."""
    return source if glsl == "es" else source.replace("#version 300 es\n", "#version 330 core\n", 1)


def build(ctx, shader, fill, glsl):
    """The program of the variant `fill`, in the first dialect that compiles: (program, dialect,
    the errors of those that did not)."""
    fragment = shader.replace("#version 300 es\n", f"#version 300 es\n#define FILL {fill}\n", 1)
    errors = []
    for g in ["es", "330"] if glsl == "auto" else [glsl]:
        try:
            return ctx.program(vertex_shader=dialect(VERTEX, g),
                               fragment_shader=dialect(fragment, g)), g, errors
        except moderngl.Error as e:
            errors.append(f"{g}: {str(e)[:400]}")
    return None, None, errors


class Draw:
    """The page's WebGL state for one scene: the program, its uniforms, textures, camera."""

    def __init__(self, ctx, program, scene, width, height):
        self.ctx, self.p, self.scene, self.w, self.h = ctx, program, scene, width, height
        self.vbo = ctx.buffer(np.array([-1, -1, 1, -1, -1, 1, 1, 1], "f4").tobytes())
        self.vao = ctx.vertex_array(program, [(self.vbo, "2f", "corner")])
        self.fbo = ctx.simple_framebuffer((width, height), components=4)
        self.load()

    def set(self, name, value):
        u = self.p.get(name, None)
        if u is None:
            return  # not active in this variant, as the page's set() skips it
        if isinstance(value, np.ndarray):
            n = u.array_length * u.dimension
            flat = value.reshape(-1)[:n]
            # An array shorter than the shader's is padded, as WebGL leaves the rest zero.
            flat = np.concatenate([flat, np.zeros(n - flat.size, flat.dtype)])
            u.write(flat.tobytes())
        else:
            u.value = value

    def upload(self, name, rows, texels):
        """view.js's upload: `texels` texels a row, 1024 a line (texture units stay bound)."""
        lines = -(-max(1, len(rows) * texels) // 1024)
        data = np.zeros(1024 * lines * 4, "f4")
        for i, v in enumerate(rows):
            data[4 * texels * i:4 * texels * i + len(v)] = v
        t = self.ctx.texture((1024, lines), 4, data.tobytes(), dtype="f4")
        t.filter = (moderngl.NEAREST, moderngl.NEAREST)
        t.use(location=TEXTURES.index(name))
        self.set(name, TEXTURES.index(name))

    def load(self):
        """view.js's loadScene."""
        s = self.scene
        lo, hi = [list(b) for b in s["bounds"]]
        f = s.get("fill")
        if f:
            nudge = 2e-5 * (1 + max(h - l for l, h in zip(lo, hi)))
            lo = [x - nudge for x in lo]
            hi = [x + nudge for x in hi]
            corners = lambda t: [t[0], t[1], t[2], 0, t[3], t[4], t[5], 0, t[6], t[7], t[8], 0]  # noqa: E731
            self.set("uNudge", nudge)
            self.upload("uPartNodes", f["part"]["nodes"], 2)
            self.upload("uPartTris", [corners(t) for t in f["part"]["triangles"]], 3)
            self.upload("uKeepNodes", f["keep"]["nodes"], 2)
            self.upload("uKeepTris", [corners(t) for t in f["keep"]["triangles"]], 3)
            self.set("uKeepCount", len(f["keep"]["triangles"]))
            self.set("uSkin", f["skin"])
            self.set("uFillBlend", f["blend"])
            self.set("uCap", f["cap"])
            drains = np.zeros(128, "f4")
            for i, d in enumerate(f["drains"][:16]):
                drains[8 * i:8 * i + 8] = [d[0], d[1], d[2], d[6], d[3], d[4], d[5], 0]
            self.set("uDrainCount", min(16, len(f["drains"])))
            self.set("uDrains", drains)
        self.set("uBoxMin", tuple(lo))
        self.set("uBoxMax", tuple(hi))
        self.set("uStep", 0.1 * s["voxel"])
        self.set("uAoReach", s["cell"] / 6)
        if s["kind"] == "tpms":
            t = s["tpms"]
            terms = np.array(t["terms"], "f4").reshape(-1)
            self.set("uKind", 0)
            self.set("uTerms", terms)
            self.set("uTermCount", len(t["terms"]))
            self.set("uSheet", 1 if t["sheet"] else 0)
            self.set("uLipschitz", t["lipschitz"])
            cell, phase = t["size"], t["phase"]
        else:
            st = s["struts"]
            self.upload("uStruts", st["struts"], 2)
            self.set("uKind", 1)
            if st["bins_per_axis"] != 4:
                raise ValueError("the shader takes 4 bins per axis")
            self.set("uBinStart", np.array(st["bins"], "i4"))
            self.set("uBlend", st["blend"])
            cell, phase = st["size"], st["phase"]
        self.set("uReach", s["reach"])
        self.set("uCell", tuple(cell))
        self.set("uPhase", tuple(phase))

    def camera(self, azimuth, elevation):
        """view.js's camera(): eye, forward, right, up."""
        lo, hi = (np.array(b, float) for b in self.scene["bounds"])
        centre, radius = 0.5 * (lo + hi), 0.5 * np.linalg.norm(hi - lo)
        aspect = self.w / self.h
        half_v = math.radians(0.5 * FOV)
        half = math.atan(math.tan(half_v) * aspect) if aspect < 1 else half_v
        distance = 1.04 * radius / math.sin(half)
        az, el = math.radians(azimuth), math.radians(elevation)
        towards = np.array([math.sin(az) * math.cos(el), -math.cos(az) * math.cos(el), math.sin(el)])
        forward = -towards
        up_world = np.array([-math.sin(az), math.cos(az), 0]) if abs(math.cos(el)) < 1e-9 \
            else np.array([0.0, 0.0, 1.0])
        right = np.cross(forward, up_world)
        right /= np.linalg.norm(right)
        return centre + distance * towards, forward, right, np.cross(right, forward)

    def frame(self, azimuth, elevation, section):
        """view.js's draw(), then one pixel read back (as state.bench)."""
        self.fbo.use()
        self.ctx.viewport = (0, 0, self.w, self.h)
        eye, forward, right, up = self.camera(azimuth, elevation)
        self.set("uSize", (float(self.w), float(self.h)))
        for name, v in (("uEye", eye), ("uForward", forward), ("uRight", right), ("uUp", up)):
            self.set(name, tuple(float(x) for x in v))
        self.set("uTanHalf", math.tan(math.radians(0.5 * FOV)))
        self.set("uLevel", self.scene["level"])
        self.set("uSectionOn", 1 if section else 0)
        if section:
            axis, at, above = section
            n = [0.0, 0.0, 0.0]
            n[axis] = -1.0 if above else 1.0
            self.set("uSectionN", tuple(n))
            self.set("uSectionD", -at if above else at)
        self.fbo.clear(0.0, 0.0, 0.0, 0.0)
        self.vao.render(moderngl.TRIANGLE_STRIP, vertices=4)
        return self.fbo.read(viewport=(0, 0, 1, 1), components=4)

    def pixels(self):
        """The last frame, RGBA, top row first."""
        a = np.frombuffer(self.fbo.read(components=4), np.uint8).reshape(self.h, self.w, 4)
        return a[::-1].copy()


def section_of(text, scene):
    """'z=25' (keep below) or 'z>25' (keep above), as the page's section control, whose slider
    steps by a thousandth of the box."""
    above = ">" in text
    axis, at = text.replace(">", "=").replace("<", "=").split("=")
    a = "xyz".index(axis.strip().lower())
    lo, hi = scene["bounds"][0][a], scene["bounds"][1][a]
    step = (hi - lo) / 1000
    at = min(hi, max(lo, lo + round((float(at) - lo) / step) * step))
    return a, at, above


def timed(work, n):
    """Seconds that n calls of work take."""
    t0 = time.perf_counter()
    for _ in range(n):
        work()
    return time.perf_counter() - t0


def reference_mask(path, shape):
    if path.endswith(".npy"):
        m = np.isfinite(np.load(path))
    elif path.endswith(".mask"):
        m = np.frombuffer(open(path, "rb").read().strip(), np.uint8).reshape(shape) == ord("1")
    else:
        m = np.asarray(Image.open(path).convert("RGBA"))[..., 3] > 127
    if m.shape != shape:
        raise ValueError(f"{path}: {m.shape}, not {shape}")
    return m


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("shader")
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--frames", type=int, default=10)
    ap.add_argument("--out", default="frames-out")
    ap.add_argument("--width", type=int, default=800)
    ap.add_argument("--height", type=int, default=600)
    ap.add_argument("--azimuth", type=float, default=45.0)
    ap.add_argument("--elevation", type=float, default=math.degrees(math.atan(1 / math.sqrt(2))))
    ap.add_argument("--section", action="append", default=[], help="NAME:AXIS=MM (cube10:z=25 "
                    "when none is given, as benches/view.rs)")
    ap.add_argument("--check", action="append", default=[], help="NAME=REF (.npy, .mask, .png)")
    ap.add_argument("--glsl", choices=["auto", "es", "330"], default="auto")
    a = ap.parse_args()
    sections = dict(s.split(":", 1) for s in (a.section or ["cube10:z=25"]))
    checks = dict(c.split("=", 1) for c in a.check)
    os.makedirs(a.out, exist_ok=True)

    ctx = moderngl.create_standalone_context(backend="egl")
    shader = open(a.shader).read()
    out = {"renderer": ctx.info["GL_RENDERER"], "vendor": ctx.info["GL_VENDOR"],
           "version": ctx.info["GL_VERSION"], "context": "EGL (device platform), desktop GL core",
           "size": [a.width, a.height], "frames": a.frames, "azimuth": a.azimuth,
           "elevation": a.elevation, "scenes": {}}
    for path in a.scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        scene = json.load(open(path))
        t0 = time.perf_counter()
        program, glsl, errors = build(ctx, shader, 1 if scene.get("fill") else 0, a.glsl)
        if program is None:
            out["scenes"][name] = {"error": errors}
            continue
        d = Draw(ctx, program, scene, a.width, a.height)
        section = section_of(sections[name], scene) if name in sections else None
        compile_s = time.perf_counter() - t0
        warm = timed(lambda: d.frame(a.azimuth, a.elevation, section), 1)
        seconds = timed(lambda: d.frame(a.azimuth, a.elevation, section), a.frames)
        px = d.pixels()
        Image.fromarray(px, "RGBA").save(os.path.join(a.out, name + ".png"))
        hit = px[..., 3] > 127
        r = {"fps": a.frames / seconds, "ms_per_frame": 1000 * seconds / a.frames,
             "warmup_ms": 1000 * warm, "compile_and_upload_ms": 1000 * compile_s,
             "glsl": "300 es" if glsl == "es" else "330 core", "hits": float(hit.mean()),
             "section": section, "error": errors or None}
        if name in checks:
            ref = reference_mask(checks[name], hit.shape)
            r["agreement"] = float((ref == hit).mean())
            r["reference"] = checks[name]
        out["scenes"][name] = r
        print(f"{name}: {r['fps']:.2f} fps", file=sys.stderr, flush=True)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
