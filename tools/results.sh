#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Regenerates docs/results.md from scratch: builds Release (build/), runs every measurement and writes the
# tables, each after the exact command that produced it, with a short summary computed from the numbers.
#
#   tools/results.sh                 # everything (~10-15 min on the shared 2-core machine, plus compiling)
#   tools/results.sh --only 2,4      # some sections only, written to build/results-partial.md (development)
#
# Environment: JOBS (default 2), HBVH_RESULTS_1M=1 also runs the 10^6-primitive scale bench (~4-6 min).
# Progress goes to stderr. Nothing here is specific to one machine except the note it writes.
set -euo pipefail

cd "$(dirname "$0")/.."
root=$(pwd)
build=build
jobs=${JOBS:-2}
only=""
if [[ ${1:-} == --only ]]; then only=${2:?"--only needs a list like 1,3"}; fi
output=docs/results.md
[[ -n $only ]] && output=$build/results-partial.md

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
start_time=$(date +%s)
log() { printf '[results %4ss] %s\n' "$(($(date +%s) - start_time))" "$*" >&2; }
wanted() { [[ -z $only || ",$only," == *",$1,"* ]]; }

# ---------------------------------------------------------------------------------------------------------
# Build: Release, only the targets used here. hbvh_peers exists only when Bullet (float64) and FCL are found.
log "configuring $build (Release)"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >"$work/cmake.log" 2>&1 || { cat "$work/cmake.log" >&2; exit 1; }
targets=(hbvh_cli hbvh_bench hbvh_objectives)
have_peers=0
if [[ $(cmake --build "$build" --target help 2>/dev/null) == *hbvh_peers* ]]; then
    targets+=(hbvh_peers)
    have_peers=1
fi
log "building ${targets[*]} with -j$jobs"
build_start=$(date +%s)
cmake --build "$build" -j"$jobs" --target "${targets[@]}" >"$work/build.log" 2>&1 || { tail -50 "$work/build.log" >&2; exit 1; }
log "built in $(($(date +%s) - build_start)) s"
measure_start=$(date +%s)

hbvh=$build/apps/hbvh/hbvh
bench=$build/bench/hbvh_bench
peers=$build/bench/hbvh_peers
shared_models=../shared/data/models

# The document is assembled in pieces; `emit` appends Markdown, `command_block` shows a command.
doc=$work/results.md
: >"$doc"
emit() { printf '%s\n' "$@" >>"$doc"; }
command_block() { emit '```' "$*" '```' ''; }

# Summaries are computed from the saved outputs by this helper (python3, standard library only).
summarise() { python3 "$work/summarise.py" "$@" >>"$doc"; emit ''; }
cat >"$work/summarise.py" <<'PYTHON'
import json, statistics, sys

def markdown_rows(path):
    """The rows of the first Markdown table in `path`, as dicts keyed by the header."""
    header, rows = None, []
    for line in open(path):
        line = line.strip()
        if not line.startswith('|'):
            if header and rows: break
            continue
        cells = [c.strip() for c in line.strip('|').split('|')]
        if header is None: header = cells
        elif set(line) <= set('|-: '): continue
        else: rows.append(dict(zip(header, cells)))
    return rows

def number(text):
    try: return float(text.split()[0].replace(',', ''))
    except (ValueError, IndexError): return None

def span(values, fmt='{:.1f}'):
    values = [v for v in values if v is not None]
    if not values: return 'n/a'
    lo, hi = min(values), max(values)
    return fmt.format(lo) if lo == hi else (fmt.format(lo) + '–' + fmt.format(hi))

def compare_summary(path, label):
    rows = [r for r in markdown_rows(path) if not r['time (ms)'].startswith(('error', 'skipped'))]
    models = list(dict.fromkeys(r['model'] for r in rows))
    by = {(r['model'], r['algorithm']): r for r in rows}
    gap = lambda r: number(r['gap to optimum']) if r['gap to optimum'] != '-' else None
    with_opt = [m for m in models if any(gap(r) is not None for r in rows if r['model'] == m)]
    out = []
    if with_opt:
        parts = []
        for a in ['auto', 'bnb-exact', 'bnb-enlarge', 'bnb-tightest', 'scale', 'merge', 'split', 'insertion-haber', 'obbtree']:
            gaps = [gap(by[(m, a)]) for m in with_opt if (m, a) in by]
            if any(g is not None for g in gaps): parts.append(f'{a} {span(gaps)} %')
        out.append(f'{label}: the optimum is known for {len(with_opt)} of {len(models)} models '
                   f'({", ".join(with_opt)}). Gap to it, over those models: ' + '; '.join(parts) + '.')
        opt_times = [(number(by[(m, 'optimal')]['time (ms)']), m) for m in with_opt if (m, 'optimal') in by]
        if opt_times:
            t, m = max(opt_times)
            out.append(f'The optimum itself took up to {t / 1000:.1f} s ({m}, {by[(m, "optimal")]["primitives"]} primitives).')
    else:
        out.append(f'{label}: no model is small enough for the optimum, so there is no gap column.')
    # The cheapest builder other than optimal, per model, and where hbvh's own (auto, bnb-exact) lose.
    wins = {}
    for m in models:
        rs = [r for r in rows if r['model'] == m and r['algorithm'] not in ('optimal', 'auto')]
        best = min(number(r['cost']) for r in rs)
        for r in rs:
            if number(r['cost']) <= best * (1 + 1e-6): wins[r['algorithm']] = wins.get(r['algorithm'], 0) + 1
    out.append('Cheapest builder other than optimal (ties counted for each): ' +
               ', '.join(f'{a} on {n} of {len(models)}' for a, n in sorted(wins.items(), key=lambda w: -w[1])) + '.')
    losses = {}
    for m in models:
        for ours in ['auto', 'bnb-exact']:
            if (m, ours) not in by: continue
            mine = number(by[(m, ours)]['cost'])
            better = tuple(a for (mm, a), r in by.items() if mm == m and a not in ('optimal', 'auto', 'bnb-exact')
                           and number(r['cost']) < mine * (1 - 1e-6))
            if better: losses.setdefault((m, better), []).append(ours)
    out.append('Where hbvh loses on cost: ' + ('; '.join(f'{m}: {"/".join(o)} beaten by {", ".join(b)}'
                                                        for (m, b), o in losses.items()) if losses else
               'nowhere — auto and bnb-exact are at least as cheap as every survey and classic builder on every model') + '.')
    slow = [(number(r['time (ms)']), r['model'], r['algorithm']) for r in rows]
    t, m, a = max(slow)
    out.append(f'Slowest row: {a} on {m} ({t / 1000:.1f} s).')
    budget = [f'{r["algorithm"]} on {r["model"]}' for r in rows if 'budget hit' in r['time (ms)']]
    if budget: out.append('Rows that stopped at their budget (best found, not proven): ' + ', '.join(budget) + '.')
    print(' '.join(out))

def scale_summary(path):
    rows = [r for r in markdown_rows(path) if not r['time (ms)'].startswith(('error', 'skipped'))]
    out, losses = [], []
    for m in dict.fromkeys(r['model'] for r in rows):
        by = {r['algorithm']: r for r in rows if r['model'] == m}
        if 'scale' not in by: continue
        s_cost, s_time = number(by['scale']['cost']), number(by['scale']['time (ms)'])
        text = f'{by["scale"]["primitives"]} primitives: scale {s_time / 1000:.2f} s'
        for other in ('merge', 'split'):
            if other in by:
                ratio = s_cost / number(by[other]['cost'])
                text += (f'; cost {ratio:.2f}× {other}\'s ({"cheaper" if ratio < 1 else "dearer"}), '
                         f'{other} took {number(by[other]["time (ms)"]) / 1000:.2f} s')
        if 'auto' in by: text += f'; auto {number(by["auto"]["time (ms)"]) / 1000:.2f} s'
        out.append(text)
        for other in ('merge', 'split'):
            if other in by and number(by[other]['cost']) < s_cost:
                losses.append(f'{other} builds a {s_cost / number(by[other]["cost"]):.2f}× cheaper tree at '
                              f'{by["scale"]["primitives"]} primitives (in {number(by[other]["time (ms)"]) / 1000:.1f} s '
                              f'vs {s_time / 1000:.1f} s)')
    print('Measured: ' + '. '.join(out) + '.')
    if losses: print('Where hbvh loses: ' + '; '.join(losses) + '.')
    if any('budget hit' in r['time (ms)'] for r in rows):
        print('"budget hit" on scale rows means some windows\' solve_exact stopped at its per-window node budget '
              '(20 000 search nodes) and kept the best cover found: deterministic, no time limit involved.')

def simulate_summary(path):
    data = json.load(open(path))
    out, losses, cuts = [], [], []
    for model in dict.fromkeys(d['model'] for d in data):
        rows = [d for d in data if d['model'] == model]
        base = next((d for d in rows if d['label'] == 'two-level query'), None)
        best_m = min(rows, key=lambda d: d['moving']['mean_query_ms'])
        best_t = min(rows, key=lambda d: d['total']['mean_query_ms'])
        out.append(f'{model}: fastest moving {best_m["label"]} ({1000 * best_m["moving"]["mean_query_ms"]:.2f} µs), '
                   f'fastest totally colliding {best_t["label"]} ({1000 * best_t["total"]["mean_query_ms"]:.2f} µs)')
        if base:
            trees = [d for d in rows if d is not base and d['label'] != 'two-level']
            slower = [d['label'] for d in trees if d['moving']['mean_query_ms'] > base['moving']['mean_query_ms']]
            if slower: losses.append(f'{model} ({", ".join(slower)})')
            prim = [d['moving']['mean_primitive_tests'] for d in trees]
            cuts.append(f'{model} {base["moving"]["mean_primitive_tests"]:.0f} → {span(prim)}')
    print('; '.join(out) + '.')
    if all(min(rows_, key=lambda d: d['total']['mean_query_ms'])['label'] == 'two-level query'
           for rows_ in ([d for d in data if d['model'] == m] for m in dict.fromkeys(d['model'] for d in data))):
        print('In the totally colliding case the two-level query always wins: mode `first` stops at the first '
              'overlapping pair, which it reaches after one root test, while tandem traversal descends first.')
    if cuts:
        print('Primitive tests per moving query, two-level query → hierarchies: ' + '; '.join(cuts) + '.')
    if losses:
        print(f'Where hbvh loses: real hierarchies are slower than the survey\'s two-level query in the moving case on '
              f'{len(losses)} of {len(out)} models: ' + '; '.join(losses) + '. At 13–27 primitives the pair tests '
              'that the hierarchy saves are cheap (sphere pre-test), and its inner-node tests are not.')
    else:
        print('Every hierarchy beats the two-level query in the moving case.')

def bench_json(path):
    return {b['name']: b for b in json.load(open(path))['benchmarks'] if b.get('run_type', 'iteration') == 'iteration'}

def solver_summary(path):
    b = bench_json(path)
    level = lambda name: int(name.split('/')[1])
    exact = {level(n): v for n, v in b.items() if n.startswith('BM_solve_exact_level/') and 'error_occurred' not in v}
    ref = {level(n): v for n, v in b.items() if n.startswith('BM_solve_reference_level/') and 'error_occurred' not in v}
    common = sorted(set(exact) & set(ref))
    if not common:
        print('No level timings.'); return
    te = sum(exact[l]['real_time'] for l in common); tr = sum(ref[l]['real_time'] for l in common)
    per = ', '.join(f'{int(exact[l]["nodes"])} nodes {ref[l]["real_time"] / exact[l]["real_time"]:.3g}×' for l in common)
    hits = [str(int(ref[l]['nodes'])) for l in common if ref[l].get('budget_hit', 0) > 0]
    print(f'Over the {len(common)} levels the reference B&B took {tr:.4g} ms and solve_exact {te:.3g} ms in all: '
          f'solve_exact is {tr / te:.3g}× faster (per level, reference / exact: {per}). '
          'The total is dominated by the first, biggest level; on the small top levels both take microseconds.'
          + (f' budget_hit = 1 on the level(s) of {", ".join(hits)} nodes: the reference stopped at its budget or '
             'found no exact cover there (the driver then falls back).' if hits else ''))

def fit_summary(path):
    b = bench_json(path)
    out = []
    for name, v in sorted(b.items()):
        if not name.startswith('FitObb/best/'): continue
        model = name.split('/')[-1]
        c = b.get('FitObb/covariance/' + model)
        if not c: continue
        out.append(f'{model}: root {v["root_volume"] / c["root_volume"]:.2f}×, pairs {v["pairs_volume"] / c["pairs_volume"]:.2f}× '
                   f'the covariance volume, at {v["real_time"] / c["real_time"]:.1f}× its time')
    print('hbvh\'s fit_obb against the covariance OBB (volume ratio < 1 = tighter): ' + '; '.join(out) + '.')

def peers_summary(path):
    lines = open(path).read().split('### Query')
    builds = markdown_rows_text(lines[0]); queries = markdown_rows_text(lines[1]) if len(lines) > 1 else []
    out = []
    for regime in dict.fromkeys(r['regime'] for r in queries):
        rs = [r for r in queries if r['regime'] == regime]
        bt = [number(r['bullet/hbvh']) for r in rs]; fc = [number(r['fcl/hbvh']) for r in rs]
        lose = [r['object'] for r in rs if (number(r['bullet/hbvh']) or 9) < 1 or (number(r['fcl/hbvh']) or 9) < 1]
        text = f'{regime}: Bullet/hbvh {span(bt, "{:.2f}")}, FCL/hbvh {span(fc, "{:.2f}")}'
        if lose: text += f' (hbvh slower on {", ".join(lose)})'
        out.append(text)
    print('Query time ratios (peer / hbvh, above 1 = hbvh faster) per regime: ' + '; '.join(out) + '.')
    # The honest comparison: each peer at its fastest (FCL's traversal alone, without moving its objects;
    # Bullet with its compound algorithm found once and reused), and the worst row against the faster peer.
    # The ratios are the bench's own columns, from unrounded times (the µs columns are rounded to 0.01, which
    # moves a ratio of 0.2 µs rows by up to 5 %); FCL collide-only's has no column of its own.
    honest = []
    for r in queries:
        fcl_only, hbvh = number(r['fcl collide only']), number(r['hbvh'])
        honest.append((number(r['faster peer/hbvh']), number(r['bullet/hbvh']), fcl_only / hbvh, r))
    if honest:
        out = []
        for regime in dict.fromkeys(r['regime'] for r in queries):
            rs = [h for h in honest if h[3]['regime'] == regime]
            out.append(f'{regime}: Bullet/hbvh {span([h[1] for h in rs], "{:.2f}")}, '
                       f'FCL collide-only/hbvh {span([h[2] for h in rs], "{:.2f}")}, '
                       f'faster peer/hbvh {span([h[0] for h in rs], "{:.2f}")}')
        print('Against each peer\'s fastest honest timing (FCL collide-only, Bullet with its cached compound algorithm): '
              + '; '.join(out) + '.')
        worst = min(honest, key=lambda h: h[0])
        print(f'Worst row: {worst[3]["object"]} {worst[3]["regime"]}, faster peer/hbvh = {worst[0]:.2f} '
              f'(hbvh {number(worst[3]["hbvh"]):.2f} µs, Bullet {number(worst[3]["bullet"]):.2f}, '
              f'FCL collide-only {number(worst[3]["fcl collide only"]):.2f}).')
    loses = [f'{r["object"]} {r["regime"]} ({number(r["fcl collide only"]):.2f} vs {number(r["hbvh"]):.2f} µs)'
             for r in queries if number(r['fcl collide only']) < number(r['hbvh'])]
    if loses:
        print('FCL\'s traversal alone (without moving its n objects, which a rigid compound would not need) is '
              'faster than hbvh on: ' + ', '.join(loses) + '.')
    # Issue 13's bars against hbvh's own two-level query: <= 0.8x when partly overlapping or near, <= 1.2x
    # at total overlap, in both modes.
    def bar(r): return 1.2 if r['regime'] == 'total' else 0.8
    for mode, column in (('all', 'tandem/2-level'), ('first', 'tandem/2-level first')):
        if not queries or column not in queries[0]: continue
        parts = []
        for regime in dict.fromkeys(r['regime'] for r in queries):
            rs = [number(r[column]) for r in queries if r['regime'] == regime]
            parts.append(f'{regime} {span(rs, "{:.2f}")}')
        miss = [f'{r["object"]} {r["regime"]} ({number(r[column]):.2f})' for r in queries if number(r[column]) > bar(r)]
        print(f'Tandem traversal / two-level query, mode {mode}: ' + '; '.join(parts) + '. '
              + (f'Above the bar (0.8, total 1.2) on {len(miss)} of {len(queries)} rows: {", ".join(miss)}.' if miss
                 else 'Within the bar (0.8, total 1.2) on every row.'))
    below = [f'{r["object"]} {r["regime"]} ({h[0]:.2f})' for h in honest for r in [h[3]] if h[0] < 2.0]
    if below:
        print(f'Faster peer / hbvh below 2 on {len(below)} of {len(queries)} rows: {", ".join(below)}.')
    if builds:
        bt = [number(r['hbvh ms']) / max(number(r['bullet ms']), 1e-9) for r in builds]
        cost = [number(r['hbvh cost']) / number(r['bullet cost']) for r in builds]
        costf = [number(r['hbvh cost']) / number(r['fcl cost']) for r in builds]
        print(f'Build: hbvh takes {span(bt, "{:.0f}")}× Bullet\'s time (it fits and optimises volumes; Bullet inserts AABBs '
              f'into a dynamic tree): that is where hbvh loses most clearly. Its Eq. 2 cost is {span(cost, "{:.2f}")}× '
              f'Bullet\'s and {span(costf, "{:.2f}")}× FCL\'s (their costs are of AABB trees, by the same formula).')
        dearer = [r['object'] for r in builds if number(r['hbvh cost']) > min(number(r['bullet cost']), number(r['fcl cost']))]
        if dearer: print('hbvh\'s tree costs more than a peer\'s on: ' + ', '.join(dearer) + '.')

def markdown_rows_text(text):
    import tempfile, os
    with tempfile.NamedTemporaryFile('w', delete=False) as f: f.write(text)
    try: return markdown_rows(f.name)
    finally: os.unlink(f.name)

def simulate_table(path):
    data = json.load(open(path))
    print('| model | builder | moving µs/query | moving BV tests | moving prim. tests | total µs/query | total BV tests | total prim. tests |')
    print('| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |')
    for d in data:
        m, t = d['moving'], d['total']
        print(f'| {d["model"]} | {d["label"]} | {1000 * m["mean_query_ms"]:.2f} | {m["mean_bv_tests"]:.1f} | '
              f'{m["mean_primitive_tests"]:.1f} | {1000 * t["mean_query_ms"]:.2f} | {t["mean_bv_tests"]:.1f} | '
              f'{t["mean_primitive_tests"]:.1f} |')

def bench_table(path, prefix, *counters):
    b = bench_json(path)
    print('| benchmark | wall time | ' + ' | '.join(counters) + ' |')
    print('| --- | ---: |' + ' ---: |' * len(counters))
    for name, v in b.items():
        if not name.startswith(prefix): continue
        if 'error_occurred' in v:
            if v.get('error_message') == 'no such level': continue  # the model has fewer levels
            print(f'| {name} | {v.get("error_message", "error")} |' + ' |' * len(counters)); continue
        cells = [f'{v[c]:.6g}' if c in v else '' for c in counters]
        print(f'| {name} | {v["real_time"]:.4g} {v["time_unit"]} | ' + ' | '.join(cells) + ' |')

def objectives_summary(path):
    rows = markdown_rows(path)
    def column(key): return [(r['object'], number(r[key])) for r in rows if number(r[key]) is not None]
    for key in ['ρ Eq. 2 / moving', 'ρ calibrated / moving', 'ρ Eq. 2 / total', 'ρ calibrated / total',
                'ρ child-priced / moving', 'ρ child-priced / total', 'ρ retest / moving', 'ρ BV tests / moving',
                'ρ fitted counts / moving']:
        values = column(key)
        if not values: continue
        worst = min(values, key=lambda v: v[1])
        above = sum(1 for _, v in values if v >= 0.8)
        print(f"- {key}: median {statistics.median(v for _, v in values):+.2f}, worst {worst[1]:+.2f} ({worst[0]}), "
              f"at least 0.8 on {above} of {len(values)} objects.")
    ratios = [v for _, v in column('auto/cal ÷ auto, moving')]
    if ratios:
        print(f"- `auto` built for the calibrated objective against `auto` for Eq. 2, moving phase: time ratio "
              f"{min(ratios):.2f}-{max(ratios):.2f}, median {statistics.median(ratios):.2f}.")

globals()[sys.argv[1]](*sys.argv[2:])
PYTHON


# ---------------------------------------------------------------------------------------------------------
emit "# Results" ""
emit "Generated by \`tools/results.sh\` on $(date -u '+%Y-%m-%d %H:%M UTC') from commit" \
     "\`$(git rev-parse --short HEAD)\`$(git diff --quiet HEAD -- src include apps bench 2>/dev/null || echo ' (with uncommitted changes)')." \
     "Do not edit by hand: rerun the script. Release build (\`-DCMAKE_BUILD_TYPE=Release\`), binaries in \`$build/\`." \
     "Machine: $(nproc) cores shared with up to three other engineers' builds and benchmarks" \
     "(load average $(cut -d' ' -f1-3 /proc/loadavg) at the start), so wall times are indicative (tens of percent);" \
     "Eq. 2 costs, BV-test counts and gaps are deterministic." ""
emit "Cost is the survey's Eq. 2 (sum over inner nodes of children × BV volume); *gap to optimum* is" \
     "cost / optimum − 1, where the optimum is the \`optimal\` builder's proven minimum (subset DP, at most" \
     "18 primitives by default). \"MC\" is the survey's merging-candidate count." ""

# ---------------------------------------------------------------------------------------------------------
# 1. Survey Tables 2-3.
if wanted 1; then
    log "section 1: survey Tables 2-3 on data/models"
    emit "## 1. Survey Tables 2–3: every builder on the bundled models" ""
    command_block "$hbvh compare data/models/*.xml --markdown"
    "$hbvh" compare data/models/*.xml --markdown >"$work/tables23.md"
    cat "$work/tables23.md" >>"$doc"
    emit ""
    emit "**What it shows.** Times are medians of 5 builds (a build over 1 s is timed once)."
    summarise compare_summary "$work/tables23.md" "Bundled models"

    if [[ -d $shared_models ]]; then
        log "section 1: real models from $shared_models"
        emit "### Real models (MJCF/URDF from \`$shared_models\`)" ""
        # Size each model (a two-level build is instant), then split at 30 primitives: the survey's B&B
        # builders, bnb-exact and optimal are exponential or O(n^3) in fits and take minutes above that.
        small=() big=()
        for f in "$shared_models"/*.xml "$shared_models"/*.urdf; do
            [[ -e $f ]] || continue
            n=$("$hbvh" compare "$f" --algorithms two-level --repeat 1 --json 2>/dev/null |
                python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["primitives"])' || echo 0)
            if ((n == 0)); then log "  skipping $f (does not load)"; continue; fi
            if ((n <= 30)); then small+=("$f"); else big+=("$f"); fi
        done
        cheap=two-level,merge,insertion,insertion-haber,split,obbtree,scale,auto
        emit "Models of at most 30 primitives get every builder; larger ones only \`$cheap\`" \
             "(the survey's B&B builders, \`bnb-exact\` and \`optimal\` are exponential or need O(n³) fits and take" \
             "minutes there). \`auto\` above 24 primitives keeps the cheapest of a portfolio (led by \`scale\` up to 32, by \`insertion-haber\` above)" \
             "(docs/scale.md §5). A model that does not load is left out." ""
        if ((${#small[@]} > 0)); then
            command_block "$hbvh compare ${small[*]} --markdown --repeat 3"
            "$hbvh" compare "${small[@]}" --markdown --repeat 3 >"$work/real_small.md"
            cat "$work/real_small.md" >>"$doc"
            emit ""
            summarise compare_summary "$work/real_small.md" "Real models up to 30 primitives"
        fi
        if ((${#big[@]} > 0)); then
            command_block "$hbvh compare ${big[*]} --algorithms $cheap --markdown --repeat 3"
            "$hbvh" compare "${big[@]}" --algorithms "$cheap" --markdown --repeat 3 >"$work/real_big.md"
            cat "$work/real_big.md" >>"$doc"
            emit ""
            summarise compare_summary "$work/real_big.md" "Real models above 30 primitives"
        fi
    else
        emit "_Real models skipped: \`$shared_models\` is absent._" ""
    fi
fi

# ---------------------------------------------------------------------------------------------------------
# 2. Scale.
if wanted 2; then
    log "section 2: scale"
    emit "## 2. Scale: generated scenes" ""
    for spec in 1000:1 20000:1; do
        count=${spec%%:*} seed=${spec##*:}
        "$hbvh" generate --count "$count" --seed "$seed" -o "$work/scene-$count.xml"
        cp "$work/scene-$count.xml" "$work/generated-$count.xml"
    done
    emit "Scenes: \`$hbvh generate --count N --seed 1 -o generated-N.xml\` for N = 1 000 and 20 000." ""
    command_block "$hbvh compare generated-1000.xml generated-20000.xml --algorithms scale,merge,split,auto --repeat 1 --markdown"
    log "  compare at 1 000 and 20 000 primitives (merge at 20 000 takes ~0.5-2 min)"
    "$hbvh" compare "$work/generated-1000.xml" "$work/generated-20000.xml" --algorithms scale,merge,split,auto \
        --repeat 1 --markdown >"$work/scale.md"
    cat "$work/scale.md" >>"$doc"
    emit ""
    emit "**What it shows.** One build each (\`--repeat 1\`); \`auto\` is the cheaper of \`binned\` and \`split\` at 1000 primitives and \`binned\` alone above 2000 (docs/scale.md §9)."
    summarise scale_summary "$work/scale.md"
    if [[ ${HBVH_RESULTS_1M:-0} == 1 ]]; then
        log "  10^6 bench (several minutes)"
        command_block "$bench --benchmark_filter='scale_build/1M' --benchmark_out=scale1m.json --benchmark_out_format=json"
        "$bench" --benchmark_filter='scale_build/1M' --benchmark_out="$work/scale1m.json" --benchmark_out_format=json >&2
        python3 "$work/summarise.py" bench_table "$work/scale1m.json" scale_build cost primitives >>"$doc"
        emit ""
    else
        emit "10⁶ primitives: not run by default (one build takes several minutes here; \`HBVH_RESULTS_1M=1" \
             "tools/results.sh\` adds \`$bench --benchmark_filter='scale_build/1M'\`; docs/scale.md has a probe)." ""
    fi
fi

# ---------------------------------------------------------------------------------------------------------
# 3. Table 4: queries.
if wanted 3; then
    log "section 3: Table 4 (hbvh simulate)"
    emit "## 3. Survey Table 4: collision queries" ""
    query_builders=(two-level merge split bnb-enlarge bnb-exact auto)
    emit "Two copies of each model, the survey's §5.3 benchmark (docs/queries.md): the mean over the first 1 000" \
         "queries whose root BVs overlap while one copy moves, and over 1 000 totally colliding queries" \
         "(same pose). Mode \`first\` (does it collide). \"two-level query\" is the survey's Two-Level method" \
         "(root test, then all primitive pairs); the other rows are tandem traversal of that builder's tree." ""
    emit "Each tree is built once and saved; the simulation runs 3 times on it and the table gives the median" \
         "of the 3 mean query times (counts are identical between runs)." ""
    command_block "for m in data/models/*.xml; do for a in ${query_builders[*]}; do" \
                  "  $hbvh build \$m -a \$a -o tree.xml" \
                  "  for run in 1 2 3; do $hbvh simulate tree.xml --collisions 1000 --json; done  # + --two-level-query on the two-level tree" \
                  "done; done"
    echo '[' >"$work/simulate.json"
    first=1
    for m in data/models/*.xml; do
        model=$(basename "$m" .xml)
        log "  $model"
        for a in "${query_builders[@]}" two-level-query; do
            extra=() label=$a
            if [[ $a == two-level-query ]]; then a=two-level extra=(--two-level-query) label="two-level query"; fi
            "$hbvh" build "$m" -a "$a" -o "$work/tree.xml" 2>/dev/null
            runs=()
            for run in 1 2 3; do runs+=("$("$hbvh" simulate "$work/tree.xml" "${extra[@]}" --collisions 1000 --json)"); done
            ((first)) || echo ',' >>"$work/simulate.json"
            first=0
            python3 - "$model" "$label" "${runs[@]}" >>"$work/simulate.json" <<'MEDIAN'
import json, statistics, sys
runs = [json.loads(r) for r in sys.argv[3:]]
out = runs[0]
for case in ('moving', 'total'):
    out[case]['mean_query_ms'] = statistics.median(r[case]['mean_query_ms'] for r in runs)
out['model'], out['label'] = sys.argv[1], sys.argv[2]
print(json.dumps(out))
MEDIAN
        done
    done
    echo ']' >>"$work/simulate.json"
    python3 "$work/summarise.py" simulate_table "$work/simulate.json" >>"$doc"
    emit ""
    emit "**What it shows.**"
    summarise simulate_summary "$work/simulate.json"
fi

# ---------------------------------------------------------------------------------------------------------
# 4. Solver.
if wanted 4; then
    log "section 4: exact solver vs reference B&B (up to ~1 min)"
    emit "## 4. Set-partition solver: solve_exact vs the survey's branch and bound" ""
    emit "The level instances B&B-Enlarge's driver produces on tie_interceptor.xml (27 primitives), each solved" \
         "by hbvh's \`solve_exact\` and by the survey's reference branch and bound (10 s budget per level)." ""
    filter='BM_solve_exact_level|BM_solve_reference_level'
    command_block "$bench --benchmark_filter='$filter' --benchmark_out=solver.json --benchmark_out_format=json"
    "$bench" --benchmark_filter="$filter" --benchmark_out="$work/solver.json" --benchmark_out_format=json >/dev/null 2>&1
    python3 "$work/summarise.py" bench_table "$work/solver.json" BM_solve nodes budget_hit >>"$doc"
    emit ""
    emit "**What it shows.**"
    summarise solver_summary "$work/solver.json"
fi

# ---------------------------------------------------------------------------------------------------------
# 5. Fitting.
if wanted 5; then
    log "section 5: OBB fitting"
    emit "## 5. Fitting tightness: OBBs" ""
    emit "Every pair of primitives and the whole model of each bundled model, fitted with Gottschalk's covariance" \
         "OBB (the survey's fitter) and with hbvh's \`fit_obb\` (several candidate frames, docs/fitting.md)." ""
    command_block "$bench --benchmark_filter=FitObb --benchmark_out=fit.json --benchmark_out_format=json"
    "$bench" --benchmark_filter=FitObb --benchmark_out="$work/fit.json" --benchmark_out_format=json >/dev/null 2>&1
    python3 "$work/summarise.py" bench_table "$work/fit.json" FitObb root_volume pairs_volume fits >>"$doc"
    emit ""
    emit "**What it shows.**"
    summarise fit_summary "$work/fit.json"
fi

# ---------------------------------------------------------------------------------------------------------
# 6. Peers.
if wanted 6; then
    emit "## 6. Peers: Bullet and FCL" ""
    if ((have_peers)); then
        log "section 6: hbvh_peers (1-3 min)"
        emit "Each object built by hbvh (\`auto\`), Bullet (\`btCompoundShape\` with its dynamic AABB tree) and FCL" \
             "(\`DynamicAABBTreeCollisionManager\`), then queried against a copy of itself on seeded poses;" \
             "every method reports all overlapping pairs. Method details: docs/peers.md." ""
        command_block "$peers --markdown --poses 32 --repetitions 11"
        "$peers" --markdown --poses 32 --repetitions 11 >"$work/peers.md" 2>"$work/peers.err" ||
            emit "_hbvh_peers exited non-zero: $(tail -1 "$work/peers.err")_"
        cat "$work/peers.md" >>"$doc"
        emit ""
        emit "**What it shows.**"
        summarise peers_summary "$work/peers.md"
    else
        emit "_Skipped: hbvh_peers was not configured (Bullet float64 or FCL not found)._" ""
    fi
fi

# ---------------------------------------------------------------------------------------------------------
# 7. Which cost predicts query time.
if wanted 7; then
    emit "## 7. Which cost predicts query time" ""
    log "section 7: hbvh_objectives (under a minute on the 2-core machine of 2026-12-03)"
    emit "Every registered builder's tree of each object, built for Eq. 2 and for the calibrated objective" \
         "(\`NAME/cal\`: Minkowski measure and measured per-kind weights, docs/metrics.md \"Calibrated cost\"), timed on the same 300 recorded queries of the" \
         "survey's simulator per phase (\`first\` mode; the mover's path recorded once with the Two-Level query, so" \
         "that it depends on no tree; fastest of 7 passes, each timed as a whole). ρ is Spearman's rank" \
         "correlation between a cost and the measured time over all the object's trees (1: the cost orders the" \
         "trees exactly as their speed). *Child-priced* is a candidate cost that no builder minimises yet: each" \
         "inner node's Minkowski measure times the sum of its children's test weights (an inner child's kind's" \
         "weight, a leaf 0.5; docs/metrics.md). Three columns are yardsticks, not costs: *retest*, the same moving" \
         "queries timed again after both phases (how far the trees' times stand apart from the timing's noise;" \
         "no cost can rank them better than this); *BV tests*, the number of BV tests those queries made" \
         "(what Eq. 2 models: a cost that counted them exactly would reach this column's ρ and no more); and" \
         "*fitted counts*, the time predicted by a least-squares fit of the object's own times on the BV tests and" \
         "primitive tests its trees' queries made (plus a constant): fitted to the times it is scored against, an" \
         "upper estimate of what any cost built from those two counts can reach." \
         "The last two columns: time of \`auto\` built for the calibrated" \
         "objective over \`auto\` built for Eq. 2. The survey's searches (\`bnb-*\`, \`optimal\`) run up to 100" \
         "primitives and 5 s per build." ""
    emit "The calibrated objective's per-kind weights are measured first, on this machine, by \`hbvh calibrate\`" \
         "(the tandem traversal's inner-node test cost for each pair of kinds; a kind's weight is its test against" \
         "its own kind, relative to an AABB's against an AABB; docs/metrics.md \"Per-kind weights\"):" ""
    emit '```' "$hbvh calibrate -o weights.txt" \
        "build/bench/hbvh_objectives --markdown --summary --collisions 300 --build-seconds 5 --type-weight @weights.txt" \
        '```' ''
    "$hbvh" calibrate -o "$work/weights.txt" >"$work/calibrate.txt"
    emit '```' "$(grep -v '^weights written' "$work/calibrate.txt")" '```' ''
    "$build/bench/hbvh_objectives" --markdown --summary --collisions 300 --build-seconds 5 \
        --type-weight "@$work/weights.txt" >"$work/objectives.md" 2>"$work/objectives.err" ||
        emit "_hbvh_objectives exited non-zero: $(tail -1 "$work/objectives.err")_"
    cat "$work/objectives.md" >>"$doc"
    emit "" "**What it shows.**"
    summarise objectives_summary "$work/objectives.md"
fi

emit "---" "" "tools/results.sh took $(($(date +%s) - measure_start)) s of measurement on this run (after a" \
     "$((measure_start - build_start)) s build step)."
mkdir -p "$(dirname "$output")"
cp "$doc" "$output"
log "wrote $output"
