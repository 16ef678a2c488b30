#!/usr/bin/env bash
# Release build of taut_bench and a full benchmark run (5 repetitions, aggregates only), written to
#   OUT_DIR/results.json   Google Benchmark's JSON (every aggregate and counter)
#   OUT_DIR/summary.md     tables: taut vs Bullet's deformable world, tet-beam scaling with the
#                          fitted growth exponent, point-vs-shape narrowphase time and accuracy
# Usage: scripts/run_bench.sh [OUT_DIR] [-- extra taut_bench flags, e.g. --benchmark_filter=...]
#   (default OUT_DIR docs/bench; build dir build/bench, or TAUT_BENCH_BUILD_DIR). The full run
#   takes ~30 min on 2 cores, most of it in the 51k and 103k tet scaling sizes.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"

out_dir="${TAUT_ROOT}/docs/bench"
if (($# > 0)) && [[ "$1" != "--" ]]; then
  out_dir="$1"
  shift
fi
if (($# > 0)) && [[ "$1" == "--" ]]; then
  shift
fi
mkdir -p "${out_dir}"
out_dir="$(cd "${out_dir}" && pwd)"
cd "${TAUT_ROOT}"
build_dir="${TAUT_BENCH_BUILD_DIR:-build/bench}"

taut_stage "Installing dependencies"
taut_install_deps
if ! command -v python3 >/dev/null; then
  echo "error: python3 is needed for the summary (apt-get install python3)" >&2
  exit 1
fi
taut_stage "Configuring ${build_dir} (Release, benchmarks only)"
cmake -G Ninja -S . -B "${build_dir}" -DCMAKE_BUILD_TYPE=Release -DTAUT_BUILD_BENCH=ON \
  -DTAUT_BUILD_TESTS=OFF -DTAUT_BUILD_DEMOS=OFF >/dev/null
taut_stage "Building taut_bench (-j${TAUT_JOBS})"
cmake --build "${build_dir}" -j"${TAUT_JOBS}" --target taut_bench

taut_stage "Running taut_bench (5 repetitions) into ${out_dir}/results.json"
"${build_dir}/bench/taut_bench" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out="${out_dir}/results.json" --benchmark_out_format=json "$@"

taut_stage "Writing ${out_dir}/summary.md"
python3 - "${out_dir}/results.json" "${out_dir}/summary.md" <<'PY'
import json, math, re, sys

data = json.load(open(sys.argv[1]))
median = {}
errors = {}
for b in data["benchmarks"]:
    # "BM_X/10/min_time:0.500/repeats:5/manual_time" -> "BM_X/10"
    name = b.get("run_name", b["name"])
    name = re.sub(r"/(repeats|min_time|manual_time|real_time)[^/]*", "", name)
    if b.get("error_occurred"):
        errors[name] = b.get("error_message", "error")
    elif b.get("aggregate_name") == "median":
        median[name] = b

def rows(prefix):
    return [(n, b) for n, b in median.items() if n.startswith(prefix)]

def fmt(x, digits=3):
    return f"{x:.{digits}g}"

ctx = data["context"]
out = ["# Benchmark results", "",
       f"Machine: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, "
       f"load average {', '.join(fmt(x, 2) for x in ctx.get('load_avg', []))} at the start; "
       f"{ctx.get('date')}. Medians of 5 repetitions. Produced by `scripts/run_bench.sh`.", ""]

out += ["## taut DeformableWorld vs Bullet 3.24 btDeformableMultiBodyDynamicsWorld", "",
        "Per-step thread CPU time, same mesh, masses, material and h = 1/240 s "
        "(bench/bullet_deformable_bench.cc).", "",
        "| scene | tets | taut ms/step | Bullet ms/step | taut / Bullet | sanity |",
        "|---|---:|---:|---:|---:|---|"]
for name, b in rows("BM_BeamTautVsBullet") + rows("BM_BallDropTautVsBullet"):
    if "Beam" in name:
        sanity = (f"tip z: taut {fmt(b['taut_tip_z_m'])} m, Bullet {fmt(b['bullet_tip_z_m'])} m, "
                  f"distance between the tips {fmt(b['tip_difference_m'])} m, Bullet moves: "
                  f"{'yes' if b['bullet_moves'] > 0.5 else 'NO'}")
        scene = "beam"
    else:
        sanity = (f"lowest node z: taut {fmt(b['taut_lowest_m'])} m, "
                  f"Bullet {fmt(b['bullet_lowest_m'])} m")
        scene = "ball drop"
    out.append(f"| {scene} | {int(b['tets'])} | {fmt(b['taut_ms_per_step'])} | "
               f"{fmt(b['bullet_ms_per_step'])} | {fmt(b['taut_over_bullet'])} | {sanity} |")

scaling = sorted(rows("BM_TetBeamScaling"), key=lambda nb: nb[1]["tets"])
if scaling:
    out += ["", "## Unconstrained tet beam step vs size", "",
            "CPU time per step (bench/tet_scaling_bench.cc); the exponent p is the least-squares "
            "slope of log(time) against log(tets).", "",
            "| tets | DOFs | cells | ms/step (CPU) | ms/step (wall) |", "|---:|---:|---|---:|---:|"]
    to_ms = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
    points = []
    for _, b in scaling:
        unit = to_ms[b["time_unit"]]
        cells = f"{int(b['cells_x'])}x{int(b['cells_y'])}x{int(b['cells_z'])}"
        out.append(f"| {int(b['tets'])} | {int(b['dofs'])} | {cells} | "
                   f"{fmt(b['cpu_time'] * unit)} | {fmt(b['real_time'] * unit)} |")
        points.append((math.log(b["tets"]), math.log(b["cpu_time"] * unit)))

    def slope(pts):
        n = len(pts)
        mx = sum(x for x, _ in pts) / n
        my = sum(y for _, y in pts) / n
        return sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)

    out.append("")
    out.append(f"Growth exponent p (time ~ tets^p): all sizes {slope(points):.2f}")
    half = points[len(points) // 2:]
    if len(half) >= 2:
        out[-1] += (f"; largest {len(half)} sizes ({int(math.exp(half[0][0]))}+ tets) "
                    f"{slope(half):.2f}")
    out[-1] += "."

shapes = ["sphere", "box", "capsule", "cylinder", "hull"]
methods = []
for name, _ in rows("BM_PointDistance/"):
    m = name.split("/")[1]
    if m not in methods:
        methods.append(m)
if methods:
    out += ["", "## Point-vs-shape signed distance", "",
            "Per query CPU time over 1,024 points (512 inside, 512 outside); accuracy against the "
            "closed form: max |gap error| [m], sign errors, normal errors (> 0.01 rad), queries "
            "without a gap (bench/narrowphase_bench.cc).", "",
            "| method | " + " | ".join(shapes) + " |", "|---|" + "---|" * len(shapes)]
    for m in methods:
        cells = []
        for s in shapes:
            key = f"BM_PointDistance/{m}/{s}"
            b = median.get(key)
            if b is None:
                err = errors.get(key)
                cells.append(f"n/a ({err})" if err else "-")
                continue
            cells.append(f"{b['s_per_query'] * 1e9:.0f} ns; err {fmt(b['gap_err_max'], 2)}; "
                         f"sign {int(b['sign_errors'])}; normal {int(b['normal_errors'])}; "
                         f"no gap {int(b['no_answer'])}")
        out.append(f"| {m} | " + " | ".join(cells) + " |")

other = [n for n in median if not n.startswith(("BM_BeamTautVsBullet", "BM_BallDropTautVsBullet",
                                                 "BM_TetBeamScaling", "BM_PointDistance/"))]
if other:
    out += ["", "## Other benchmarks", "", "| benchmark | time (wall) | time (CPU) |",
            "|---|---:|---:|"]
    for n in other:
        b = median[n]
        out.append(f"| {n} | {fmt(b['real_time'])} {b['time_unit']} | "
                   f"{fmt(b['cpu_time'])} {b['time_unit']} |")

open(sys.argv[2], "w").write("\n".join(out) + "\n")
print("\n".join(out))
PY
