#!/bin/bash
# The device run of frames.py (from the repo root, on a lent GPU machine through the tool `run`,
# carrying .gl (Debian's glvnd EGL/GL/GLES debs) and .whl (moderngl, glcontext cp312 wheels)):
# unpacks them, prints the GPU, and times the four scenes twice, writing JSON, PNGs and a log
# to $OUT (at most 8 files come back).
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
    --target /tmp/site .whl/*.whl && export PYTHONPATH=/tmp/site || exit 1
export PYTHONUNBUFFERED=1
nvidia-smi -L
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
probe() { python3 -c "import moderngl; c = moderngl.create_standalone_context(backend='egl'); print('EGL:', c.info['GL_RENDERER'], '|', c.info['GL_VERSION'])"; }
if ! probe; then
    echo "no EGL driver found: naming NVIDIA's vendor file"
    export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    probe || { ls /usr/share/glvnd/egl_vendor.d /usr/local/nvidia/share/glvnd/egl_vendor.d; ldconfig -p | grep -i -e egl -e nvidia | head -30; exit 2; }
fi
cd benches/support/gpu || exit 1
FRAMES=${FRAMES:-100}
for i in 1 2; do
    timeout 120 python3 frames.py ../../../src/render/view/page/trace.glsl \
        scenes/bcc10.json scenes/bcc100.json scenes/gyroid10.json scenes/cube10.json \
        --frames "$FRAMES" --out "$OUT" > "$OUT/gpu$i.json" 2>> "$OUT/log.txt"
    echo "run $i: rc $?"; cat "$OUT/gpu$i.json"
done
cat "$OUT/log.txt"
