#version 300 es
// latvox view: a lattice part sphere-traced from its implicit description, per pixel — the
// same method as `latvox render` (src/render/trace.rs): a ray clipped by the part's box and the
// section plane advances by the field's clearance (never less than a quarter pixel), a crossing
// is refined by false position, normals are the field's gradient, shading is a key and a fill
// light with ambient occlusion read from the field.
//
// TPMS: F = Σ coef · Π_a f_a(2π k_a u_a) from the part's terms; the clearance is |F − t| over a
// bound on |∇F|. Struts: a point maps into one cell (q = (p − phase) mod size − size/2) and the
// distance is the least over the augmented cell's struts (the cell's own and every copy that
// reaches it), capped at the reach: a strut outside the list is farther than the reach, so the
// capped distance is a safe step across cells (a random Voronoi net is one cell covering its
// box). Voronoi walls: a point's distance to its cell's boundary is the least over the other
// seeds of its distance to their bisector plane with the nearest, less half the thickness, the
// pore through a wall cut out of it. Filled parts: a ray is cast at the part's
// surface through its BVH, and only inside it is the lattice sphere-traced, joined to a skin by
// the depth below the surface (the BVH's distance, capped), less the drain holes; kept solids
// are cast at as meshes.
precision highp float;
precision highp int;
precision highp sampler2D;

uniform vec2 uSize;
uniform vec3 uEye;
uniform vec3 uForward;
uniform vec3 uRight;
uniform vec3 uUp;
uniform float uTanHalf;
uniform vec3 uBoxMin;
uniform vec3 uBoxMax;
uniform int uKind;          // 0 TPMS, 1 struts, 2 Voronoi walls
uniform float uLevel;       // TPMS level, strut radius or wall thickness (mm)
uniform vec3 uCell;         // cell size, mm
uniform vec3 uPhase;        // a cell's lower corner, mm
// TPMS
uniform int uTermCount;
uniform vec4 uTerms[10];    // coef, 3k + f per axis (f: 0 one, 1 cos, 2 sin)
uniform int uSheet;
uniform float uLipschitz;
// Struts, listed per bin of the cell: two texels per strut, (a, factor) and (b, factor), 1024
// texels a row.
uniform sampler2D uStruts;
// Struts and walls: per bin of the cell (uBins per axis), where its list starts; then the end.
uniform sampler2D uBinTex;
uniform ivec3 uBins;
// Walls, listed per bin: a seed is one texel (its place from the phase, its index); a pore three
// (centre, radius), (normal, 0), (the two seeds' indices, 0, 0), with its bins' starts in
// uPoreBins.
uniform sampler2D uSeeds;
uniform sampler2D uPores;
uniform sampler2D uPoreBins;
uniform int uRepeat;        // walls: 1 where the cell repeats (a periodic foam)
uniform float uBlend;
uniform float uReach;
// Section: keep where dot(n, p) <= d.
uniform int uSectionOn;
uniform vec3 uSectionN;
uniform float uSectionD;
// Filled parts (compiled in where the page defines FILL as 1): the part's surface and the kept
// solids as BVHs (two texels per node: lower corner and first child or triangle, upper corner
// and triangle count; three per triangle).
uniform sampler2D uPartNodes;
uniform sampler2D uPartTris;
uniform sampler2D uKeepNodes;
uniform sampler2D uKeepTris;
uniform int uKeepCount;     // kept triangles (0: none)
uniform float uSkin;
uniform float uFillBlend;
uniform float uCap;         // depths are asked up to this
uniform float uNudge;       // a step past a surface a ray was cast to
uniform int uDrainCount;
uniform vec4 uDrains[32];   // per hole: (from, radius), (to, 0)
uniform float uStep;        // normal step, a tenth of a voxel
uniform float uAoReach;     // ambient occlusion reach, a sixth of a cell

out vec4 outColor;

const float TAU = 6.283185307179586;
const int MAX_STEPS = 1024;

// f(2πk u) and its derivative by u, for a factor's code 3k + f (f: 0 one, 1 cos, 2 sin).
vec2 factor(float code, float u) {
    float k = floor(code / 3.0 + 0.01);
    float f = code - 3.0 * k;
    if (f < 0.5) return vec2(1.0, 0.0);
    if (k < 0.5) return vec2(f > 1.5 ? 0.0 : 1.0, 0.0);
    // k is a whole number: the phase within one period keeps float precision far from 0.
    float x = TAU * fract(k * fract(u));
    float c = cos(x);
    float s = sin(x);
    return f < 1.5 ? vec2(c, -TAU * k * s) : vec2(s, TAU * k * c);
}

// TPMS: (value, clearance). The value is the implicit F − t (or |F| − t) over |∇F| — a distance
// estimate, capped at the reach, as the CPU renderer's — and the clearance the implicit over a
// bound on |∇F| (a safe step).
vec2 tpms(vec3 p) {
    vec3 u = (p - uPhase) / uCell;
    float F = 0.0;
    vec3 g = vec3(0.0);
    for (int i = 0; i < 10; i++) {
        if (i >= uTermCount) break;
        vec4 t = uTerms[i];
        vec2 fx = factor(t.y, u.x);
        vec2 fy = factor(t.z, u.y);
        vec2 fz = factor(t.w, u.z);
        F += t.x * fx.x * fy.x * fz.x;
        g += t.x * vec3(fx.y * fy.x * fz.x, fx.x * fy.y * fz.x, fx.x * fy.x * fz.y);
    }
    float v = (uSheet == 1 ? abs(F) : F) - uLevel;
    float norm = length(g / uCell);
    float d = norm > 1e-12 ? v / norm : sign(v) * uReach;
    return vec2(clamp(d, -uReach, uReach), abs(v) / uLipschitz);
}

vec4 fetch(sampler2D s, int i) {
    return texelFetch(s, ivec2(i % 1024, i / 1024), 0);
}

vec4 strutTexel(int i) {
    return texelFetch(uStruts, ivec2(i % 1024, i / 1024), 0);
}

// Signed distance to a strut of end radii ra, rb: a capsule, or Quilez's exact round cone.
float strutDistance(vec3 p, vec3 a, vec3 b, float ra, float rb) {
    vec3 ab = b - a;
    vec3 ap = p - a;
    float l2 = dot(ab, ab);
    if (ra == rb) {
        float t = clamp(dot(ap, ab) / l2, 0.0, 1.0);
        return length(ap - ab * t) - ra;
    }
    float rr = ra - rb;
    float a2 = l2 - rr * rr;
    float il2 = 1.0 / l2;
    float y = dot(ap, ab);
    float z = y - l2;
    vec3 w = ap * l2 - ab * y;
    float x2 = dot(w, w);
    float y2 = y * y * l2;
    float z2 = z * z * l2;
    float k = sign(rr) * rr * rr * x2;
    if (sign(z) * a2 * z2 > k) return sqrt(x2 + z2) * il2 - rb;
    if (sign(y) * a2 * y2 < k) return sqrt(x2 + y2) * il2 - ra;
    return (sqrt(x2 * a2 * il2) + y * rr) * il2 - ra;
}

float smoothMin(float a, float b, float k) {
    float h = max(k - abs(a - b), 0.0) / k;
    return min(a, b) - 0.25 * h * h * k;
}

// The bin of a point `r` of the cell (from its lower corner).
int binOf(vec3 r) {
    ivec3 c = clamp(ivec3(r / uCell * vec3(uBins)), ivec3(0), uBins - 1);
    return (c.x * uBins.y + c.y) * uBins.z + c.z;
}

int binStart(sampler2D s, int bin) {
    return int(fetch(s, bin).x);
}

vec2 struts(vec3 p) {
    vec3 r = mod(p - uPhase, uCell);
    int bin = binOf(r);
    vec3 q = r - 0.5 * uCell;
    float d = uReach;
    int end = binStart(uBinTex, bin + 1);
    for (int i = binStart(uBinTex, bin); i < end; i++) {
        vec4 a = strutTexel(2 * i);
        vec4 b = strutTexel(2 * i + 1);
        float di = strutDistance(q, a.xyz, b.xyz, uLevel * a.w, uLevel * b.w);
        d = uBlend > 0.0 ? smoothMin(d, di, uBlend) : min(d, di);
    }
    d = min(d, uReach);
    return vec2(d, abs(d));
}

vec2 walls(vec3 p) {
    vec3 r = uRepeat == 1 ? mod(p - uPhase, uCell) : p - uPhase;
    int bin = binOf(r);
    int start = binStart(uBinTex, bin);
    int end = binStart(uBinTex, bin + 1);
    float best = 1e30;
    vec4 s1 = vec4(0.0, 0.0, 0.0, -1.0);
    for (int i = start; i < end; i++) {
        vec4 s = fetch(uSeeds, i);
        vec3 e = r - s.xyz;
        float d2 = dot(e, e);
        if (d2 < best) {
            best = d2;
            s1 = s;
        }
    }
    float halfT = 0.5 * uLevel;
    float d = halfT + uReach;
    float other = -1.0;
    for (int i = start; i < end; i++) {
        vec4 s = fetch(uSeeds, i);
        if (s.w == s1.w) continue;
        float c = length(s.xyz - s1.xyz);
        vec3 e = r - s.xyz;
        float v = (dot(e, e) - best) / (2.0 * c);
        if (c > 0.0 && v < d) {
            d = v;
            other = s.w;
        }
    }
    float v = d - halfT;
    if (other >= 0.0) {
        float lo = min(s1.w, other);
        float hi = max(s1.w, other);
        int pe = binStart(uPoreBins, bin + 1);
        for (int k = binStart(uPoreBins, bin); k < pe; k++) {
            vec4 ids = fetch(uPores, 3 * k + 2);
            if (ids.x != lo || ids.y != hi) continue;
            vec4 c = fetch(uPores, 3 * k);
            vec3 n = fetch(uPores, 3 * k + 1).xyz;
            vec3 w = r - c.xyz;
            float along = dot(w, n);
            float across = sqrt(max(dot(w, w) - along * along, 0.0));
            v = max(v, min(c.w - across, halfT + uReach - abs(along)));
            break;
        }
    }
    v = min(v, uReach);
    return vec2(v, abs(v));
}

float boxValue(vec3 p) {
    vec3 d = max(uBoxMin - p, p - uBoxMax);
    vec3 o = max(d, 0.0);
    float outside = dot(o, o);
    return outside > 0.0 ? sqrt(outside) : max(d.x, max(d.y, d.z));
}

vec2 latticeVC(vec3 p) {
    // Branches, not a conditional expression: a shader compiler may evaluate both of those.
    if (uKind == 0) return tpms(p);
    if (uKind == 2) return walls(p);
    return struts(p);
}

float lattice(vec3 p) {
    return latticeVC(p).x;
}

// The clearance of max(a, b): from outside either operand, its own clearance is safe.
float interClearance(float a, float ca, float b, float cb) {
    float c = min(ca, cb);
    if (a > 0.0) c = max(c, ca);
    if (b > 0.0) c = max(c, cb);
    return c;
}

// ------------------------------------------------------------------------- BVHs (filled parts)
#if FILL

// Where the ray enters the box before `limit`, or -1.
float boxEntry(vec3 o, vec3 inv, vec3 lo, vec3 hi, float limit) {
    vec3 a = (lo - o) * inv;
    vec3 b = (hi - o) * inv;
    vec3 mn = min(a, b);
    vec3 mx = max(a, b);
    float t0 = max(0.0, max(mn.x, max(mn.y, mn.z)));
    float t1 = min(mx.x, min(mx.y, mx.z));
    return (t0 <= t1 && t0 < limit) ? t0 : -1.0;
}

// Moller-Trumbore, from either side: the distance to the triangle, or -1.
float triangleHit(vec3 o, vec3 d, vec3 a, vec3 b, vec3 c) {
    vec3 e1 = b - a;
    vec3 e2 = c - a;
    vec3 p = cross(d, e2);
    float det = dot(e1, p);
    if (abs(det) < 1e-30) return -1.0;
    float inv = 1.0 / det;
    vec3 s = o - a;
    float u = dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) return -1.0;
    vec3 q = cross(s, e1);
    float v = dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0) return -1.0;
    float t = dot(e2, q) * inv;
    return t > 0.0 ? t : -1.0;
}

const int STACK = 48;

// The nearest triangle the ray meets before tmax: its distance (or -1) and unit normal. Nearer
// child first; nodes entered beyond the nearest hit so far are skipped.
float bvhHit(sampler2D N, sampler2D T, vec3 o, vec3 d, float tmax, out vec3 normal) {
    normal = vec3(0.0, 0.0, 1.0);
    vec3 inv = 1.0 / d;
    float limit = tmax;
    int best = -1;
    if (boxEntry(o, inv, fetch(N, 0).xyz, fetch(N, 1).xyz, limit) < 0.0) return -1.0;
    int stack[STACK];
    float enter[STACK];
    stack[0] = 0;
    enter[0] = 0.0;
    int sp = 1;
    while (sp > 0) {
        sp--;
        int i = stack[sp];
        if (enter[sp] >= limit) continue;
        vec4 n0 = fetch(N, 2 * i);
        vec4 n1 = fetch(N, 2 * i + 1);
        int first = int(n0.w);
        int count = int(n1.w);
        if (count > 0) {
            for (int k = 0; k < count; k++) {
                int j = first + k;
                float t = triangleHit(o, d, fetch(T, 3 * j).xyz, fetch(T, 3 * j + 1).xyz,
                                      fetch(T, 3 * j + 2).xyz);
                if (t > 0.0 && t < limit) {
                    limit = t;
                    best = j;
                }
            }
            continue;
        }
        float ta = boxEntry(o, inv, fetch(N, 2 * first).xyz, fetch(N, 2 * first + 1).xyz, limit);
        float tb = boxEntry(o, inv, fetch(N, 2 * first + 2).xyz, fetch(N, 2 * first + 3).xyz, limit);
        if (sp + 2 > STACK) break;
        if (ta >= 0.0 && tb >= 0.0) {
            bool aFirst = ta <= tb;
            stack[sp] = aFirst ? first + 1 : first;
            enter[sp] = aFirst ? tb : ta;
            stack[sp + 1] = aFirst ? first : first + 1;
            enter[sp + 1] = aFirst ? ta : tb;
            sp += 2;
        } else if (ta >= 0.0) {
            stack[sp] = first;
            enter[sp] = ta;
            sp++;
        } else if (tb >= 0.0) {
            stack[sp] = first + 1;
            enter[sp] = tb;
            sp++;
        }
    }
    if (best < 0) return -1.0;
    vec3 a = fetch(T, 3 * best).xyz;
    vec3 n = cross(fetch(T, 3 * best + 1).xyz - a, fetch(T, 3 * best + 2).xyz - a);
    normal = length(n) > 0.0 ? normalize(n) : n;
    return limit;
}

float boxDistance2(vec3 lo, vec3 hi, vec3 p) {
    vec3 d = max(max(lo - p, p - hi), 0.0);
    return dot(d, d);
}

// The squared distance from p to the triangle (Ericson, Real-Time Collision Detection 5.1.5).
float triangleDistance2(vec3 p, vec3 a, vec3 b, vec3 c) {
    vec3 ab = b - a;
    vec3 ac = c - a;
    vec3 ap = p - a;
    float d1 = dot(ab, ap);
    float d2 = dot(ac, ap);
    vec3 q;
    if (d1 <= 0.0 && d2 <= 0.0) {
        q = a;
    } else {
        vec3 bp = p - b;
        float d3 = dot(ab, bp);
        float d4 = dot(ac, bp);
        float vc = d1 * d4 - d3 * d2;
        vec3 cp = p - c;
        float d5 = dot(ab, cp);
        float d6 = dot(ac, cp);
        float vb = d5 * d2 - d1 * d6;
        float va = d3 * d6 - d5 * d4;
        if (d3 >= 0.0 && d4 <= d3) {
            q = b;
        } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
            q = a + ab * (d1 / (d1 - d3));
        } else if (d6 >= 0.0 && d5 <= d6) {
            q = c;
        } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
            q = a + ac * (d2 / (d2 - d6));
        } else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
            q = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
        } else {
            float denom = 1.0 / (va + vb + vc);
            q = a + ab * (vb * denom) + ac * (vc * denom);
        }
    }
    vec3 e = p - q;
    return dot(e, e);
}

// The distance from p to the nearest triangle, if nearer than limit (else limit).
float bvhDistance(sampler2D N, sampler2D T, vec3 p, float limit) {
    float best2 = limit * limit;
    int stack[STACK];
    float dist[STACK];
    stack[0] = 0;
    dist[0] = boxDistance2(fetch(N, 0).xyz, fetch(N, 1).xyz, p);
    int sp = 1;
    while (sp > 0) {
        sp--;
        int i = stack[sp];
        if (dist[sp] >= best2) continue;
        vec4 n0 = fetch(N, 2 * i);
        vec4 n1 = fetch(N, 2 * i + 1);
        int first = int(n0.w);
        int count = int(n1.w);
        if (count > 0) {
            for (int k = 0; k < count; k++) {
                int j = first + k;
                best2 = min(best2, triangleDistance2(p, fetch(T, 3 * j).xyz,
                                                     fetch(T, 3 * j + 1).xyz, fetch(T, 3 * j + 2).xyz));
            }
            continue;
        }
        float da = boxDistance2(fetch(N, 2 * first).xyz, fetch(N, 2 * first + 1).xyz, p);
        float db = boxDistance2(fetch(N, 2 * first + 2).xyz, fetch(N, 2 * first + 3).xyz, p);
        if (sp + 2 > STACK) break;
        bool aFirst = da <= db;
        stack[sp] = aFirst ? first + 1 : first;
        dist[sp] = aFirst ? db : da;
        stack[sp + 1] = aFirst ? first : first + 1;
        dist[sp + 1] = aFirst ? da : db;
        sp += 2;
    }
    return sqrt(best2);
}

// Whether p is inside the closed surface: an odd number of triangles crossed by a ray from p.
bool bvhContains(sampler2D N, sampler2D T, vec3 p) {
    vec3 d = normalize(vec3(0.5773, 0.5779, 0.5767));
    vec3 inv = 1.0 / d;
    if (boxEntry(p, inv, fetch(N, 0).xyz, fetch(N, 1).xyz, 1e30) < 0.0) return false;
    int crossings = 0;
    int stack[STACK];
    stack[0] = 0;
    int sp = 1;
    while (sp > 0) {
        sp--;
        int i = stack[sp];
        vec4 n0 = fetch(N, 2 * i);
        vec4 n1 = fetch(N, 2 * i + 1);
        int first = int(n0.w);
        int count = int(n1.w);
        if (count > 0) {
            for (int k = 0; k < count; k++) {
                int j = first + k;
                if (triangleHit(p, d, fetch(T, 3 * j).xyz, fetch(T, 3 * j + 1).xyz,
                                fetch(T, 3 * j + 2).xyz) > 0.0) crossings++;
            }
            continue;
        }
        if (sp + 2 > STACK) break;
        for (int c = 0; c < 2; c++) {
            int child = first + c;
            if (boxEntry(p, inv, fetch(N, 2 * child).xyz, fetch(N, 2 * child + 1).xyz, 1e30) >= 0.0) {
                stack[sp] = child;
                sp++;
            }
        }
    }
    return crossings % 2 == 1;
}

float unionClearance(float a, float ca, float b, float cb);

// The solid inside the part at x (the skin or the lattice, less the drain holes), d its depth.
vec2 insideAt(vec3 x, float d) {
    vec2 l = latticeVC(x);
    float v;
    float c;
    if (uSkin == 0.0) {
        v = l.x;
        c = l.y;
    } else {
        float core = d - uSkin;
        c = unionClearance(core, abs(core), l.x, l.y);
        if (uFillBlend > 0.0) {
            v = smoothMin(core, l.x, uFillBlend);
            c = max(c - uFillBlend, 0.0);
        } else {
            v = min(core, l.x);
        }
    }
    for (int i = 0; i < 16; i++) {
        if (i >= uDrainCount) break;
        vec4 a = uDrains[2 * i];
        vec3 b = uDrains[2 * i + 1].xyz;
        vec3 ab = b - a.xyz;
        vec3 ap = x - a.xyz;
        float t = clamp(dot(ap, ab) / dot(ab, ab), 0.0, 1.0);
        float dh = -(length(ap - t * ab) - a.w);
        c = interClearance(v, c, dh, abs(dh));
        v = max(v, dh);
    }
    return vec2(v, c);
}

float depth(vec3 x) {
    return bvhDistance(uPartNodes, uPartTris, x, uCap);
}

vec2 inside(vec3 x) {
    return insideAt(x, uSkin > 0.0 ? depth(x) : 0.0);
}

#endif

// ------------------------------------------------------------------------- lattice blocks

vec2 scene(vec3 p) {
    vec2 f = latticeVC(p);
    float b = boxValue(p);
    float v = max(f.x, b);
    float c = interClearance(f.x, f.y, b, abs(b));
    if (uSectionOn == 1) {
        float d = dot(uSectionN, p) - uSectionD;
        c = interClearance(v, c, d, abs(d));
        v = max(v, d);
    }
    return vec2(v, c);
}

float unionClearance(float a, float ca, float b, float cb) {
    return interClearance(-a, ca, -b, cb);
}

// What sphere tracing steps through: the clipped lattice, or inside a filled part its solid.
vec2 field(vec3 p) {
#if FILL
    return inside(p);
#else
    return scene(p);
#endif
}

float sceneValue(vec3 p) {
    return field(p).x;
}

// The part of the ray inside the box (and on the kept side of the section), or (1, 0, 0);
// third, where it enters the box.
vec3 clipRay(vec3 o, vec3 dir) {
    vec3 inv = 1.0 / dir;
    vec3 lo = (uBoxMin - o) * inv;
    vec3 hi = (uBoxMax - o) * inv;
    vec3 a = min(lo, hi);
    vec3 b = max(lo, hi);
    float t0 = max(0.0, max(a.x, max(a.y, a.z)));
    float t1 = min(b.x, min(b.y, b.z));
    float entry = t0;
    if (uSectionOn == 1) {
        float d0 = dot(uSectionN, o) - uSectionD;
        float rate = dot(uSectionN, dir);
        if (abs(rate) < 1e-20) {
            if (d0 > 0.0) return vec3(1.0, 0.0, 0.0);
        } else {
            float t = -d0 / rate;
            if (rate > 0.0) t1 = min(t1, t); else t0 = max(t0, t);
        }
    }
    return vec3(t0, t1, entry);
}

float refine(vec3 o, vec3 dir, vec2 outside, vec2 inside) {
    for (int i = 0; i < 3; i++) {
        float w = outside.y > inside.y ? outside.y / (outside.y - inside.y) : 0.5;
        w = clamp(w, 0.05, 0.95);
        float m = outside.x + w * (inside.x - outside.x);
        float v = sceneValue(o + m * dir);
        if (v <= 0.0) inside = vec2(m, v); else outside = vec2(m, v);
    }
    float w = outside.y > inside.y ? outside.y / (outside.y - inside.y) : 0.5;
    return outside.x + w * (inside.x - outside.x);
}

// The first t in [t0, t1] where the ray enters the solid, or -1.
float traceSpan(vec3 o, vec3 dir, float t0, float t1, float perDistance) {
    float t = t0;
    vec2 before = vec2(t, 1e30);
    for (int i = 0; i < MAX_STEPS; i++) {
        if (t > t1) return -1.0;
        vec2 vc = field(o + t * dir);
        if (vc.x <= 0.0) {
            if (i == 0) return t;
            return refine(o, dir, before, vec2(t, vc.x));
        }
        before = vec2(t, vc.x);
        t += max(vc.y, perDistance * t);
    }
    return -1.0;
}

// The first t where the ray enters a lattice block, or -1.
float trace(vec3 o, vec3 dir, float perDistance) {
    vec3 span = clipRay(o, dir);
    if (span.x > span.y) return -1.0;
    return traceSpan(o, dir, span.x, span.y, perDistance);
}

#if FILL
bool onCut(vec3 p) {
    return uSectionOn == 1 && abs(dot(uSectionN, p) - uSectionD) <= 1e-5 * (1.0 + length(p));
}

vec3 normalAt(vec3 p);

// The first hit of a filled part (the part's solid or a kept solid), or -1; its normal, and
// whether it is on the section's cut.
float fillHit(vec3 o, vec3 dir, float perDistance, out vec3 n, out bool cap) {
    n = vec3(0.0, 0.0, 1.0);
    cap = false;
    vec3 span = clipRay(o, dir);
    if (span.x > span.y) return -1.0;
    float t0 = span.x;
    float t1 = span.y;
    // A ray that starts on the box, not on the cut nor inside the box, starts outside the part.
    bool outside = t0 == span.z && span.z > 0.0;
    float best = -1.0;
    if (uKeepCount > 0) {
        vec3 start = o + t0 * dir;
        vec3 kn;
        if (onCut(start) && bvhContains(uKeepNodes, uKeepTris, start)) {
            best = t0;
            n = uSectionN;
            cap = true;
        } else {
            float h = bvhHit(uKeepNodes, uKeepTris, start, dir, t1 - t0, kn);
            if (h >= 0.0) {
                best = t0 + h;
                n = dot(kn, dir) > 0.0 ? -kn : kn;
            }
        }
    }
    float limit = best >= 0.0 ? best : t1;
    float t = t0;
    bool within = !outside && bvhContains(uPartNodes, uPartTris, o + t0 * dir);
    for (int iter = 0; iter < 64; iter++) {
        if (t >= limit) break;
        bool entered = false;
        vec3 sn;
        if (!within) {
            float h = bvhHit(uPartNodes, uPartTris, o + t * dir, dir, limit - t, sn);
            if (h < 0.0) break;
            t += h;
            entered = true;
        }
        vec3 ignored;
        float h2 = bvhHit(uPartNodes, uPartTris, o + (t + uNudge) * dir, dir, limit - t, ignored);
        float exitT = h2 < 0.0 ? limit : t + uNudge + h2;
        float th = traceSpan(o, dir, t, exitT, perDistance);
        if (th >= 0.0) {
            vec3 p = o + th * dir;
            cap = false;
            if (th == t && entered) {
                n = dot(sn, dir) > 0.0 ? -sn : sn;
            } else if (th == t && onCut(p)) {
                n = uSectionN;
                cap = true;
            } else {
                n = normalAt(p);
            }
            return th;
        }
        // Out of the part (through a drain hole, or at the end of the span).
        t = exitT + uNudge;
        within = false;
    }
    return best;
}
#endif

vec3 normalAt(vec3 p) {
    float h = uStep;
    vec2 k = vec2(1.0, -1.0);
    vec3 g = k.xyy * sceneValue(p + h * k.xyy) + k.yyx * sceneValue(p + h * k.yyx)
           + k.yxy * sceneValue(p + h * k.yxy) + k.xxx * sceneValue(p + h * k.xxx);
    float n = length(g);
    return n > 0.0 ? g / n : vec3(0.0, 0.0, 1.0);
}

float openness(vec3 p, vec3 n) {
    // None on a filled part's outer surface.
#if FILL
    if (depth(p) < 5.0 * uStep) return 1.0;
#endif
    float occ = 0.0;
    float weight = 1.0;
    for (int k = 1; k <= 5; k++) {
        float h = 0.2 * uAoReach * float(k);
        vec3 q = p + h * n;
        float v = sceneValue(q);
#if FILL
        if (uSectionOn == 1) v = max(v, dot(uSectionN, q) - uSectionD);
#endif
        occ += weight * max(h - v, 0.0) / h;
        weight *= 0.6;
    }
    return clamp(1.0 - 0.45 * occ, 0.0, 1.0);
}

void main() {
    float u = (2.0 * gl_FragCoord.x / uSize.x - 1.0) * uTanHalf * uSize.x / uSize.y;
    float v = (2.0 * gl_FragCoord.y / uSize.y - 1.0) * uTanHalf;
    vec3 dir = normalize(uForward + u * uRight + v * uUp);
    float pixel = 2.0 * uTanHalf / uSize.y;
    vec3 n;
    bool cap = false;
    float t;
#if FILL
    t = fillHit(uEye, dir, 0.25 * pixel, n, cap);
#else
    t = trace(uEye, dir, 0.25 * pixel);
#endif
    if (t < 0.0) {
        outColor = vec4(0.0);
        return;
    }
    vec3 p = uEye + t * dir;
#if !FILL
    {
        float tol = 0.25 * pixel * t;
        if (uSectionOn == 1) {
            float d = dot(uSectionN, p) - uSectionD;
            cap = abs(d) < uStep + 2.0 * tol && lattice(p) <= d + uStep;
        }
        n = cap ? uSectionN : normalAt(p);
    }
#endif
    vec3 keyLight = normalize(-uForward + 0.8 * uUp - 0.6 * uRight);
    vec3 fillLight = normalize(-uForward - 0.2 * uUp + 0.9 * uRight);
    float open = openness(p, n);
    float shade = (0.22 + 0.68 * max(dot(n, keyLight), 0.0) + 0.25 * max(dot(n, fillLight), 0.0))
                * (0.35 + 0.65 * open);
    vec3 base = cap ? vec3(0.86, 0.46, 0.34) : vec3(0.60, 0.66, 0.76);
    outColor = vec4(clamp(base * shade, 0.0, 1.0), 1.0);
}
