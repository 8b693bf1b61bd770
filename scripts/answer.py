"""The answer a results folder leads with: per scene (and count, and run of an experiment), which method pops
least and which is the cheapest within a popping budget, in sentences whose every number is a cell of summary.csv
or pairs.csv; and the decision table beside them. scripts/plot.py puts both at the top of report.html.

The rule and the words are those of the summary `lodbench run` prints (src/results/answer.rs; docs/measurement.md,
"The answer first"), so the terminal and the report say the same, and scripts/tests/test_answer.py checks that they
do:
  - candidates: every method but the references (`reference`, `reference-flat`, ...), with a largest lodpop;
  - the hard switch: `discrete` where it ran, else the baseline;
  - no method is named where a transition spans fewer than 2 frames (transition_frames_min): one sentence says so;
  - the budget: the run's --budget-lodpop (run.json), else half the hard switch's largest lodpop;
  - costs: the all-frames paired ratios (summary.csv's ratio_to_baseline, pairs.csv's ratio); a cost is called
    different only where its 95 % interval excludes 1.

Numbers are formatted by unit (`sig3`: at least 3 significant figures, `thousands`, `ratio_text`). Every number of a
sentence and of the decision table is a `Value`: its text and where it comes from (file, row, columns, and an
operation: `half` for the default budget, `inv` for a ratio read the other way round), which report.html writes as
data- attributes for the browser test to check against the CSVs.
"""
import math
import re

from lodbench_results import PAIRS_CSV, RUN_JSON, SUMMARY_CSV, num

# The fewest frames a transition must span for a blending method to act (src/results/answer.rs).
MIN_TRANSITION_FRAMES = 2

# summary.csv's columns that name a row besides the swept variables (and a merged folder's adapter).
KEY = ("scene", "method", "count")


def sig3(x) -> str:
    """At least 3 significant figures, never in exponent form (src/results/answer.rs's sig3)."""
    if x is None or x != x or x in (float("inf"), float("-inf")):
        return "-"
    if x == 0:
        return "0"
    d = max(0, 2 - math.floor(math.log10(abs(x))))
    return f"{x:.{d}f}"


def thousands(x) -> str:
    if x is None or x != x:
        return "-"
    return f"{round(x):,}"


def ratio_text(r, lo=None, hi=None) -> str:
    if r is None or r != r:
        return "-"
    if lo is None or hi is None or lo != lo or hi != hi:
        return f"{r:.2f}"
    return f"{r:.2f} [{lo:.2f}, {hi:.2f}]"


class Value:
    """A number as shown, and the cells it comes from: `file` (summary.csv or pairs.csv), `row` (the columns that
    find the row), `cols` (one column, or ratio, lo, hi), `fmt` (sig3, thousands, ratio) and `op` ("", "half",
    "inv")."""

    def __init__(self, text, file, row, cols, fmt, op=""):
        self.text, self.file, self.row, self.cols, self.fmt, self.op = text, file, row, cols, fmt, op

    def __str__(self):
        return self.text


def summary_value(r, variables, col, fmt="sig3", op=""):
    row = {k: r[k] for k in (*variables, *KEY)}
    if fmt == "ratio":
        cols = (col, f"{col}_ci95_lo", f"{col}_ci95_hi")
        return Value(ratio_text(num(r.get(cols[0])), num(r.get(cols[1])), num(r.get(cols[2]))), SUMMARY_CSV, row,
                     cols, fmt)
    x = num(r.get(col))
    if op == "half":
        x = x / 2
    text = thousands(x) if fmt == "thousands" else sig3(x)
    return Value(text, SUMMARY_CSV, row, (col,), fmt, op)


def is_candidate(method: str) -> bool:
    return not re.sub(r"#\d+$", "", method).startswith("reference")


def cost(r):
    """A row's time over the baseline's, all frames (infinite where not measured, so it sorts last)."""
    x = num(r.get("ratio_to_baseline"))
    return x if x == x else float("inf")


def hard_switch(rows, baseline):
    """The hard switch the least popping is set against and the default budget halves: discrete where it ran,
    else the baseline; None where neither is among `rows`."""
    return next((r for r in rows if r["method"] == "discrete"), None) or \
        next((r for r in rows if r["method"] == baseline), None)


def blocks(summary, variables):
    """[(key, rows)]: summary rows grouped by run (swept values), scene and count, in their order."""
    out = {}
    for r in summary:
        out.setdefault((tuple(r[v] for v in variables), r["scene"], r["count"]), []).append(r)
    return list(out.items())


def block_name(key, variables, all_keys):
    values, scene, count = key
    counts = {k[2] for k in all_keys if k[0] == values and k[1] == scene}
    name = scene
    if variables:
        name += " (" + ", ".join(f"{v} {x}" for v, x in zip(variables, values)) + ")"
    if len(counts) > 1:
        name += f" (count {count})"
    return name


def and_list(names):
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + f" and {names[-1]}"


def cost_clause(r, baseline, variables):
    if r["method"] == baseline:
        return [f"it is the baseline ({baseline})"]
    x, lo, hi = (num(r.get(c)) for c in ("ratio_to_baseline", "ratio_to_baseline_ci95_lo",
                                         "ratio_to_baseline_ci95_hi"))
    v = summary_value(r, variables, "ratio_to_baseline", "ratio")
    if x != x:
        return ["its cost was not measured"]
    if lo != lo or hi != hi:
        return ["it takes ", v, f" times {baseline}'s frame time (too few rounds for an interval)"]
    if lo > 1 or hi < 1:
        return ["it takes ", v, f" times {baseline}'s frame time"]
    return [f"its frame time is not measurably different from {baseline}'s (", v, " times)"]


def versus(best, nxt, pairs, variables):
    found = None
    for p in pairs:
        if p["scene"] != best["scene"] or p["count"] != best["count"] or \
                any(p.get(v) != best[v] for v in variables):
            continue
        r, lo, hi = num(p["ratio"]), num(p["ratio_ci95_lo"]), num(p["ratio_ci95_hi"])
        if any(x != x for x in (r, lo, hi)):
            continue
        row = {k: p[k] for k in (*variables, "scene", "count", "method_a", "method_b")}
        cols = ("ratio", "ratio_ci95_lo", "ratio_ci95_hi")
        if (p["method_a"], p["method_b"]) == (best["method"], nxt["method"]):
            found = (r, lo, hi, row, cols, "")
        elif (p["method_a"], p["method_b"]) == (nxt["method"], best["method"]):
            found = (1 / r, 1 / hi, 1 / lo, row, cols, "inv")
        if found:
            break
    if found is None:
        return [f" {nxt['method']} is the next within it (no paired ratio of the two)."]
    r, lo, hi, row, cols, op = found
    # best's time over next's; "faster" in hyperfine's words is its inverse.
    if hi < 1:
        v = Value(ratio_text(1 / r, 1 / hi, 1 / lo), PAIRS_CSV, row, cols, "ratio", "" if op else "inv")
        return [f" {best['method']} ran ", v, f" times faster than {nxt['method']}, the next within it."]
    v = Value(ratio_text(r, lo, hi), PAIRS_CSV, row, cols, "ratio", op)
    if lo > 1:
        return [f" Paired directly, {nxt['method']} ran ", v, f" times faster than {best['method']}."]
    return [f" It is not measurably different from {nxt['method']}, the next within it (", v,
            " times its frame time)."]


def sentences(name, rows, pairs, budget, variables):
    """The sentences of one block, each a list of str and Value parts (src/results/answer.rs, block_sentences)."""
    baseline = next((r["baseline"] for r in rows if r.get("baseline")), None)
    if not baseline:
        return [[f"{name}: no baseline ran, so no paired costs (--baseline names one)."]]
    cands = [r for r in rows if is_candidate(r["method"]) and num(r.get("lodpop_max")) == num(r.get("lodpop_max"))]
    if not cands:
        return [[f"{name}: no popping measured (--quality off, or no method with LOD transitions ran)."]]

    hard = hard_switch(cands, baseline)
    room = next((int(num(r["transition_frames_min"])) for r in rows
                 if num(r.get("transition_frames_min")) == num(r.get("transition_frames_min"))), None)
    if room is not None and room < MIN_TRANSITION_FRAMES and \
            any(hard is None or r["method"] != hard["method"] for r in cands):
        return [[f"{name}: a transition here lasts {room} frame (the camera crosses a switch's band within it), too "
                 "few for a blending method to act, so this run cannot say which method pops least; give the "
                 "transitions room with --fade time --fade-frames 8, or a slower path."]]
    # Least lodpop as the sentence shows it (3 figures), the cheaper of a tie.
    least = min(cands, key=lambda r: (float(sig3(num(r["lodpop_max"]))), cost(r), num(r["lodpop_max"])))
    out = []
    if len(cands) == 1:
        # Nothing to compare its popping with: say what it is, and a budget's verdict only where one was given.
        out.append([f"{name}: {least['method']} is the only method with LOD transitions in the run, a largest "
                    "lodpop of ", summary_value(least, variables, "lodpop_max"), "; "]
                   + cost_clause(least, baseline, variables) + ["."])
        if budget is None:
            return out
        return out + within_budget(cands, least, budget, None, pairs, baseline, variables)
    s = [f"{name}: {least['method']} pops least, a largest lodpop of ",
         summary_value(least, variables, "lodpop_max")]
    # Methods whose largest lodpop reads the same to 3 figures pop as little as far as the sentence can say.
    ties = [r["method"] for r in cands if r["method"] != least["method"] and
            sig3(num(r["lodpop_max"])) == sig3(num(least["lodpop_max"]))]
    if ties:
        s.append(f" ({and_list(ties)} too, to 3 figures)")
    if hard is not None and hard["method"] != least["method"]:
        s += [f" against {hard['method']}'s ", summary_value(hard, variables, "lodpop_max")]
    out.append(s + ["; "] + cost_clause(least, baseline, variables) + ["."])
    return out + within_budget(cands, least, budget, hard, pairs, baseline, variables)


def within_budget(cands, least, budget, hard, pairs, baseline, variables):
    """The cheapest-within-the-budget sentence (none without a budget or a hard switch to halve)."""
    if budget is not None:
        b, source = Value(sig3(budget), RUN_JSON, {}, ("budget_lodpop",), "sig3"), "--budget-lodpop"
        level = budget
    elif hard is not None:
        b = summary_value(hard, variables, "lodpop_max", op="half")
        source, level = f"half of {hard['method']}'s", num(hard["lodpop_max"]) / 2
    else:
        return []
    within = sorted((r for r in cands if num(r["lodpop_max"]) <= level and
                     num(r.get("ratio_to_baseline")) == num(r.get("ratio_to_baseline"))), key=cost)
    if not within:
        return [["No method keeps its largest lodpop within ", b, f" ({source}); {least['method']} comes nearest."]]
    best = within[0]
    s = ["Within a largest lodpop of ", b, f" ({source}), {best['method']} is the cheapest: "] + \
        cost_clause(best, baseline, variables) + ["."]
    s += [" No other method is within it."] if len(within) == 1 else versus(best, within[1], pairs, variables)
    return [s]


def text(parts) -> str:
    return "".join(str(p) for p in parts)


def answers(summary, pairs, budget, variables=()):
    """[(name, key, rows, sentences)] per block of summary.csv (rows as read, methods as the runs name them).
    `budget`: the --budget-lodpop (None: the default), or a function of a block's swept values giving it."""
    budget_of = budget if callable(budget) else (lambda values: budget)
    bs = blocks(summary, variables)
    keys = [k for k, _ in bs]
    return [(block_name(k, variables, keys), k, rows,
             sentences(block_name(k, variables, keys), rows, pairs, budget_of(k[0]), variables)) for k, rows in bs]


def largest_parts(transitions, key, method, variables):
    """(coverage, shading) of the method's transition of largest lodpop in transitions.csv (nan where missing)."""
    values, scene, count = key
    best = None
    for r in transitions or []:
        if r["scene"] != scene or r["count"] != count or r["method"] != method or \
                tuple(r.get(v) for v in variables) != values:
            continue
        if best is None or num(r["lodpop_max"]) > num(best["lodpop_max"]):
            best = r
    if best is None:
        return float("nan"), float("nan")
    return num(best.get("lodpop_coverage")), num(best.get("lodpop_shading"))


DECISION_COLUMNS = ("method", "frame time, ms", "time / baseline [95 %]", "on transition frames", "triangles",
                    "largest lodpop", "its coverage part", "its shading part", "lowest JOD", "mean rmse")


def decision_rows(key, rows, transitions, jods, variables):
    """The decision table of one block: a row per method, cells as str or Value."""
    out = []
    for r in rows:
        cov, shade = largest_parts(transitions, key, r["method"], variables)
        jod = jods.get((r["scene"], r["method"], r["count"]), float("nan"))
        out.append([
            r["method"],
            summary_value(r, variables, "gpu_ms_median") if r.get("gpu_ms_median") else
            summary_value(r, variables, "cpu_ms_median"),
            summary_value(r, variables, "ratio_to_baseline", "ratio"),
            summary_value(r, variables, "ratio_to_baseline_transition", "ratio"),
            summary_value(r, variables, "triangles_mean", "thousands"),
            summary_value(r, variables, "lodpop_max"),
            sig3(cov), sig3(shade), sig3(jod),
            summary_value(r, variables, "rmse_mean"),
        ])
    return out
