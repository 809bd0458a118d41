#!/bin/bash
# The GPU run, on the lent GPU machine: the `device` tool's `run` with command `bash tools/gpu_device.sh`
# and carry [".gl", ".whl", ".gpubench"], all three made here by `tools/gpu_timing.py prepare`. From the
# repository root; writes gpu.txt, steps.txt, timings.json, timings.md and log.txt into $OUT.
#   GPU_BUDGET_S (default 320): gpu_timing starts no new (scene, setting) after this many seconds;
#   GPU_TIMEOUT_S (default 390): it is stopped after this many (timings.json holds every finished one).
# Extra arguments go to `gpu_timing.py run` (--only-scenes, --only-configs, ...). About 6.5 minutes in all
# on an H200 with the defaults: give the call a timeout_s of 480 or more.
set -u
for deb in .gl/*.deb; do dpkg -x "$deb" /; done
ldconfig
# The machine's EGL vendor file: glvnd finds no driver without it.
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl \
    || exit 1
export PYTHONPATH=/tmp/site:$PWD
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv > "$OUT/gpu.txt" 2>&1
cat "$OUT/gpu.txt"
for cells in 32 64; do
    timeout 60 python3 tools/diffusion_step_time.py --cells "$cells" --rounds 5
done > "$OUT/steps.txt" 2>&1
cat "$OUT/steps.txt"
timeout "${GPU_TIMEOUT_S:-390}" python3 tools/gpu_timing.py run --scenes .gpubench --out "$OUT" --repeat 10 \
    --budget-s "${GPU_BUDGET_S:-320}" "$@" > "$OUT/log.txt" 2>&1
echo "gpu_timing exit status $?"
grep -v '^|' "$OUT/log.txt" | head -n 80
