#!/usr/bin/env bash
# Release build of taut_bench and a full benchmark run (5 repetitions, aggregates only), written to
#   OUT_DIR/results.json   Google Benchmark's JSON (every aggregate and counter)
#   OUT_DIR/summary.md     tables: taut vs Bullet's deformable world, tet-beam scaling with the
#                          fitted growth exponent, point-vs-shape narrowphase time and accuracy,
#                          island solvers (dual / primal / auto) against the unconstrained step,
#                          real-time figures (finger steps, armadillo ms per body per frame on 1
#                          and 2 threads, bench/real_time_bench.cc)
# Usage: scripts/run_bench.sh [OUT_DIR] [--merge] [-- extra taut_bench flags, e.g.
#   --benchmark_filter=...]   (default OUT_DIR docs/bench; build dir build/bench, or
#   TAUT_BENCH_BUILD_DIR). The full run takes ~30 min on 2 cores, most of it in the 51k and 103k
#   tet scaling sizes, plus the island solver cases (bench/island_solver_bench.cc).
#   --merge: the benchmarks of this run replace those of the same name in OUT_DIR/results.json and
#   the others are kept (a partial run, e.g. --benchmark_filter=BM_IslandSolver, updates its
#   tables only). Every benchmark entry records the CPU model (lscpu), date and load of its run.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"

out_dir="${TAUT_ROOT}/docs/bench"
merge=0
if (($# > 0)) && [[ "$1" != "--" && "$1" != "--merge" ]]; then
  out_dir="$1"
  shift
fi
if (($# > 0)) && [[ "$1" == "--merge" ]]; then
  merge=1
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
# A new build dir is configured for the benchmarks only; an existing one (TAUT_BENCH_BUILD_DIR
# pointing at a development build) keeps its tests and demos, which would otherwise stop being
# rebuilt there and go stale.
if [[ -f "${build_dir}/CMakeCache.txt" ]]; then
  taut_stage "Configuring ${build_dir} (Release, its other targets kept)"
  cmake -G Ninja -S . -B "${build_dir}" -DCMAKE_BUILD_TYPE=Release -DTAUT_BUILD_BENCH=ON >/dev/null
else
  taut_stage "Configuring ${build_dir} (Release, benchmarks only)"
  cmake -G Ninja -S . -B "${build_dir}" -DCMAKE_BUILD_TYPE=Release -DTAUT_BUILD_BENCH=ON \
    -DTAUT_BUILD_TESTS=OFF -DTAUT_BUILD_DEMOS=OFF >/dev/null
fi
taut_stage "Building taut_bench (-j${TAUT_JOBS})"
cmake --build "${build_dir}" -j"${TAUT_JOBS}" --target taut_bench
taut_fix_openblas_coretype "${build_dir}/bench/taut_bench"

# Benchmarks that set their own repetitions (the island solver cases: 3, or 1 for the
# deterministic rest measurement) keep them; every other one runs 5.
taut_stage "Running taut_bench (5 repetitions) into ${out_dir}/results.json"
"${build_dir}/bench/taut_bench" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out="${out_dir}/results.run.json" --benchmark_out_format=json "$@"

taut_stage "Recording the machine$( ((merge)) && echo ", merging into ${out_dir}/results.json")"
cpu_model="$(lscpu 2>/dev/null | sed -n 's/^Model name:[[:space:]]*//p' | head -n 1)"
python3 - "${out_dir}/results.run.json" "${out_dir}/results.json" "${merge}" "${cpu_model}" <<'PY'
import json, os, sys

run = json.load(open(sys.argv[1]))
ctx = run["context"]
ctx["cpu_model"] = sys.argv[4] or "unknown"
if ctx.get("dense_kernels"):  # bench/context_bench.cc: the kernel set of plugin/dense_kernels.h
    ctx["cpu_model"] += f" (dense kernels: {ctx['dense_kernels']})"
for b in run["benchmarks"]:
    b["run_date"] = ctx.get("date")
    b["run_cpu_model"] = ctx["cpu_model"]
    b["run_load_avg"] = ctx.get("load_avg", [])
if sys.argv[3] == "1" and os.path.exists(sys.argv[2]):
    old = json.load(open(sys.argv[2]))
    names = {b.get("run_name", b["name"]) for b in run["benchmarks"]}
    kept = [b for b in old["benchmarks"] if b.get("run_name", b["name"]) not in names]
    run["benchmarks"] = kept + run["benchmarks"]
    run["context"] = old["context"]
json.dump(run, open(sys.argv[2], "w"), indent=2)
PY
rm -f "${out_dir}/results.run.json"

taut_stage "Writing ${out_dir}/summary.md"
python3 - "${out_dir}/results.json" "${out_dir}/summary.md" <<'PY'
import json, math, re, sys

data = json.load(open(sys.argv[1]))
median = {}
single = {}
errors = {}
for b in data["benchmarks"]:
    # "BM_X/10/min_time:0.500/repeats:5/manual_time" -> "BM_X/10"
    name = b.get("run_name", b["name"])
    name = re.sub(r"/(repeats|min_time|manual_time|real_time|iterations)[^/]*", "", name)
    if b.get("error_occurred"):
        errors[name] = b.get("error_message", "error")
    elif b.get("aggregate_name") == "median":
        median[name] = b
    elif b.get("run_type") == "iteration":
        single.setdefault(name, b)  # one repetition only (no aggregates): its own figures
for name, b in single.items():
    median.setdefault(name, b)

def rows(prefix):
    return [(n, b) for n, b in median.items() if n.startswith(prefix)]

def fmt(x, digits=3):
    return f"{x:.{digits}g}"

ctx = data["context"]
out = ["# Benchmark results", "",
       f"Machine: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, "
       f"load average {', '.join(fmt(x, 2) for x in ctx.get('load_avg', []))} at the start; "
       f"{ctx.get('date')}. Medians of 5 repetitions. Produced by `scripts/run_bench.sh`.", ""]

versus = rows("BM_BeamTautVsBullet") + rows("BM_BallDropTautVsBullet")
if versus:
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

# Factor + one solve with the chosen ordering (ldlt) against AMD forced (ldlt_amd), same run.
orderings = [(n, b) for n, b in rows("BM_Factorization/factor_solve/") if n.endswith("/ldlt")]
if orderings:
    first = orderings[0][1]
    out += ["", "## Factorization orderings: AMD or nested dissection", "",
            f"CPU: {first.get('run_cpu_model', 'unknown')}, run started {first.get('run_date', '?')}. "
            "Numeric factorization + one solve of A = M + h^2 K (bench/factorization_bench.cc, "
            "manual time): SparseLdlt with its chosen ordering (nested dissection where it gives "
            "L less factor work and no more nonzeros than AMD, from 3e7 multiply-adds of AMD work) "
            "against AMD forced, in the same run; and the chosen ordering's factor on two "
            "threads (ldlt_2threads: its supernodal factor's two groups of subtrees in parallel, "
            "then the supernodes above them, bitwise the same factor; split: the share of the "
            "estimated work in the two groups, 0 where the factor does not split).", "",
            "| case | DOFs | chosen | ms (chosen) | ms (AMD) | AMD / chosen | nnz(L) chosen | "
            "nnz(L) AMD | ms (2 threads) | 1 / 2 threads | split |",
            "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    to_ms = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
    for n, b in orderings:
        amd = median.get(n + "_amd")
        if amd is None:
            continue
        chosen_ms = b["real_time"] * to_ms[b["time_unit"]]
        amd_ms = amd["real_time"] * to_ms[amd["time_unit"]]
        chosen = "nested dissection" if b.get("nested_dissection", 0) > 0.5 else "AMD"
        two = median.get(n + "_2threads")
        two_ms = two["real_time"] * to_ms[two["time_unit"]] if two else None
        out.append(f"| {n.split('/')[2]} | {int(b['dofs'])} | {chosen} | {fmt(chosen_ms)} | "
                   f"{fmt(amd_ms)} | {fmt(amd_ms / chosen_ms)} | {int(b['nnz_L'])} | "
                   f"{int(amd['nnz_L'])} | {fmt(two_ms) if two else '–'} | "
                   f"{fmt(chosen_ms / two_ms) if two else '–'} | "
                   f"{fmt(b.get('split_share', 0.0))} |")

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

island = rows("BM_IslandSolver/")
if island:
    # "BM_IslandSolver/<case>[/<size>]/<path>": path none is the case's unconstrained twin.
    def split(name):
        parts = name.split("/")[1:]
        return "/".join(parts[:-1]), parts[-1]
    twin = {split(n)[0]: b for n, b in island if split(n)[1] == "none"}
    first = island[0][1]
    targets = {"tet_iso": "<= 3x", "tet_aniso": "<= 3x", "hex_0.1J": "<= 2x, <= 4 SQP",
               "slab_rest": "<= 3x", "slab_roll": "<= 3x", "rest_box": "< 0.1 mm"}
    loads = ", ".join(fmt(x, 2) for x in first.get("run_load_avg", []))
    dates = sorted({b.get("run_date") or ctx.get("date") for _, b in island})
    when = dates[0] if len(dates) == 1 else f"runs started {', '.join(dates)}"
    out += ["", "## Island solvers: constrained step vs the unconstrained step", "",
            f"CPU: {first.get('run_cpu_model', 'unknown')} ({ctx.get('num_cpus')} cores), "
            f"{when}, load average {loads} at the start of the first run. Other work shares "
            "the machine, so compare ratios within a case (its paths and its twin run back to "
            "back). bench/island_solver_bench.cc, one Release binary; each case is warmed up outside "
            "the timed loop (beams swing into their limits, slabs settle, the sphere starts "
            "rolling), then only `stepSimulation` is timed. Medians of 3 repetitions (rest_box: "
            "1, deterministic) of per-repetition medians over the timed steps.", "",
            "- ms/step: thread CPU time per step. twin: the same body stepped without limits, "
            "ground or rigid body (no rows: its unconstrained step alone), in the same run; "
            "ratio = ms/step over the twin's.",
            "- in-step ratio: sum of `ms_total` over sum of `ms_unconstrained` of the same steps "
            "(StepStats, steady clock; the `steps.csv` ratio of issue 11).",
            "- SQP / Newton: mean iterations per step; unconverged: steps with "
            "`StepStats::converged` false, of the timed steps; max viol.: max `violation_after` "
            "(C units); primal: share of islands the primal path solved.",
            "- path dual_curved: the dual path with its QPs in the metric A + G "
            "(`SqpSettings::dual_curvature`, docs/math.md §5.7).",
            "- slab_roll sanity: sphere dx is the distance it rolled in the timed steps of one "
            "repetition, z its centre height at the end (0.18 m on the undeformed slab).", "",
            "| case | elements | path | ms/step | twin ms/step | ratio | in-step ratio | "
            "SQP | Newton | PGS sweeps | rows | unconverged | max viol. | primal | target |",
            "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    order = {"none": 0, "dual": 1, "dual_curved": 2, "primal": 3, "auto": 4}
    cases = ["tet_iso", "tet_aniso", "hex_0.1J", "slab_rest", "slab_roll", "rest_box"]
    def case_key(nb):
        case, path = split(nb[0])
        base, _, size = case.partition("/")
        rank = cases.index(base) if base in cases else len(cases)
        return (rank, base, int(size) if size else 0, order.get(path, 9))
    island.sort(key=case_key)
    for name, b in island:
        case, path = split(name)
        if path == "none":
            continue
        t = twin.get(case)
        ratio = fmt(b["ms_step"] / t["ms_step"]) if t and t["ms_step"] > 0 else "-"
        extra = ""
        if "height_change_mm" in b:
            extra = f"; height change {fmt(b['height_change_mm'], 2)} mm"
        if "rigid_dx_m" in b:
            extra = (f"; sphere dx {fmt(b['rigid_dx_m'], 2)} m, z {fmt(b['rigid_z_m'], 3)} m")
        out.append(f"| {case} | {int(b['elements'])} | {path} | {fmt(b['ms_step'])} | "
                   f"{fmt(t['ms_step']) if t else '-'} | {ratio} | {fmt(b['in_step_ratio'])} | "
                   f"{b['sqp_mean']:.2f} | {b['newton_mean']:.2f} | {b['pgs_sweeps_mean']:.0f} | "
                   f"{b['rows_mean']:.0f} | {int(b['unconverged'])}/{int(b['steps'])} | "
                   f"{fmt(b['max_violation'], 2)} | {b['primal_share']:.2f} | "
                   f"{targets.get(case.split('/')[0], '')}{extra} |")
    rest = [(n, b) for n, b in island if "height_change_mm" in b]
    if rest:
        out += ["", "Rest is rest (rest_box: 1 kg rigid 0.1 m box on a 0.2 m soft block, E = 20 "
                "kPa, limits 0.96..1.04, on the ground): box height change over the last second "
                "of a 2 s rest (target < 0.1 mm), and the largest excursion in that second.", "",
                "| path | height change [mm] | max excursion [mm] | pass |", "|---|---:|---:|---|"]
        for n, b in rest:
            out.append(f"| {split(n)[1]} | {fmt(b['height_change_mm'], 3)} | "
                       f"{fmt(b['max_drift_mm'], 3)} | "
                       f"{'yes' if b['height_change_mm'] < 0.1 else 'no'} |")
    grow = {}
    for name, b in island:
        case, path = split(name)
        base, _, size = case.partition("/")
        if size:
            grow.setdefault(base, {}).setdefault(path, []).append(
                (math.log(b["elements"]), math.log(b["ms_step"]), math.log(b["ms_unc"])))
    if grow:
        out += ["", "Growth of the cost per step under mesh refinement: least-squares exponent p "
                "of ms/step ~ elements^p (twin: the unconstrained twin; stage 2: "
                "`ms_unconstrained` of the constrained steps themselves).", "",
                "| case | sizes (elements) | path | p (step) | p (stage 2 of the same steps) | "
                "p (twin) |", "|---|---|---|---:|---:|---:|"]
        def fit(pts):
            n = len(pts)
            mx = sum(x for x, _ in pts) / n
            my = sum(y for _, y in pts) / n
            den = sum((x - mx) ** 2 for x, _ in pts)
            return sum((x - mx) * (y - my) for x, y in pts) / den if den > 0 else float("nan")
        for base, paths in grow.items():
            t = paths.get("none", [])
            p_twin = fit([(x, y) for x, y, _ in t]) if len(t) >= 2 else float("nan")
            for path in ("dual", "dual_curved", "primal", "auto"):
                pts = paths.get(path, [])
                if len(pts) < 2:
                    continue
                sizes = ", ".join(str(round(math.exp(x))) for x, _, _ in sorted(pts))
                out.append(f"| {base} | {sizes} | {path} | {fit([(x, y) for x, y, _ in pts]):.2f} | "
                           f"{fit([(x, u) for x, _, u in pts]):.2f} | {p_twin:.2f} |")

finger = rows("BM_RealTimeFinger")
armadillo = sorted(rows("BM_RealTimeArmadillo/"),
                   key=lambda nb: (-nb[1]["real_time"], nb[0]))
if finger or armadillo:
    cpu = next((b.get("run_cpu_model") for _, b in finger + armadillo if b.get("run_cpu_model")),
               "unknown CPU")
    out += ["", "## Real-time targets (issue 12)", "",
            f"bench/real_time_bench.cc on the demo scenes themselves, {cpu}, "
            f"{next((b.get('run_date') for _, b in finger + armadillo), '')}; medians of 3 "
            "repetitions. Only the scenes' `Simulate` is timed (their measurements run outside).",
            ""]
for _, b in finger:
    out += ["Finger (`taut-demo finger`: 520 steps of h = 1 ms, every press; target: every step "
            "<= 1 ms), thread CPU time per step:", "",
            "| median ms | p99 ms | max ms | steps over 1 ms | unconverged |",
            "|---:|---:|---:|---:|---:|",
            f"| {fmt(b['step_median_ms'])} | {fmt(b['step_p99_ms'])} | {fmt(b['step_max_ms'])} | "
            f"{int(round(b['steps_over_1ms']))} of {int(b['steps'])} | {int(b['unconverged'])} |",
            ""]
if armadillo:
    out += ["Armadillo (`taut-demo armadillo`, three 368-hex bodies in three islands, the first "
            "second: drop, impact, toppling; target: <= 2 ms per body per 1/60 s frame), wall "
            "time of a frame's steps per body; the 2-thread runs give bitwise the same states:",
            "", "| h | threads | ms per body per frame: median | max | unconverged steps | "
            "1 thread / 2 threads |", "|---|---:|---:|---:|---:|---:|"]
    one = {}
    for n, b in armadillo:
        fields = dict(part.split(":") for part in n.split("/")[1:] if ":" in part)
        if fields.get("threads") == "1":
            one[fields.get("steps_per_frame")] = b["frame_ms_per_body"]
    for n, b in armadillo:
        fields = dict(part.split(":") for part in n.split("/")[1:] if ":" in part)
        spf = fields.get("steps_per_frame", "?")
        h = f"1/{60 * int(spf)} s" if spf.isdigit() else "?"
        speedup = (fmt(one[spf] / b["frame_ms_per_body"]) if fields.get("threads") == "2" and
                   spf in one else "–")
        out.append(f"| {h} | {fields.get('threads', '?')} | {fmt(b['frame_ms_per_body'])} | "
                   f"{fmt(b['frame_max_ms_per_body'])} | {int(b['unconverged'])} | {speedup} |")

other = [n for n in median if not n.startswith(("BM_BeamTautVsBullet", "BM_BallDropTautVsBullet",
                                                 "BM_TetBeamScaling", "BM_PointDistance/",
                                                 "BM_IslandSolver/", "BM_RealTime",
                                                 "BM_Factorization/factor_solve/"))]
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
