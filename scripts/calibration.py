"""The calibration experiment of `lodbench calibrate`: when is a level-of-detail switch seen? Four subcommands.

  page STIMULI_JSON --out DIR/index.html
      The experiment page: src/commands/calibrate/page.html with its one placeholder `__LODBENCH_STIMULI__` replaced
      by the stimuli JSON, compact, every `</` written `<\\/` (so the JSON cannot close its script tag). `lodbench
      calibrate` (Rust) makes DIR/index.html by the same substitution; this one is for tests with synthetic stimuli.

  simulate STIMULI_JSON --metric M --threshold T --slope B --lapse L --seed S [--trials-per-track N] --out FILE
      A simulated observer: P(correct) = psychometric(intensity of M; threshold T, slope B, lapse L) below, T in the
      metric's own units (for jod_popping a JOD value, e.g. 9.7). It runs the page's procedure (the weighted up-down
      staircase and the random interleaving of tracks: procedure_start / draw_trial / procedure_next and mulberry32
      below mirror the JavaScript between `// BEGIN procedure` and `// END procedure` in page.html line for line;
      scripts/tests/test_calibration.py runs both on the same outcomes and compares) and writes responses.json with
      simulated=true. The procedure's draws come from stimuli.json's procedure.seed, as on the page; the observer's
      answers from --seed.

  fit STIMULI_JSON RESPONSES_JSON... --out DIR [--bootstrap 1000] [--seed 1] [--metric M,...]
      For each metric of stimuli.json (or those named), the maximum-likelihood psychometric function pooled over
      every track and response file; a nonparametric bootstrap over trials for the 95 % interval of the threshold;
      the 5-fold held-out log-likelihood, whose highest names best_metric. Writes DIR/calibration.json and
      DIR/fit-<metric>.png, atomically (each written to a temporary file, then renamed). Bad input (an empty or
      malformed file, no valid trial, responses to other stimuli or from another display, an unknown metric) stops
      it with one line naming the file and the reason, exit code 2, before anything is written.

  trials STIMULI_JSON --metric M --threshold T --slope B --lapse L --trials 20,40,60,80 --seeds 40 --out DIR
         [--bootstrap 200] [--jobs N]
      How many trials a threshold needs, a simulation study: for each trials-per-track value and each seed 0..S-1, a
      simulated observer planted on M (simulate's, --seed the seed) fitted as `fit` does (every metric of
      stimuli.json for the best metric by held-out likelihood, the bootstrap interval of M only, the fit's --seed
      the seed). Writes DIR/trials.csv (a row per value and seed: trials_per_track, seed, total_trials, threshold,
      ci_lo, ci_hi, covered = the interval holds T, best_metric) and DIR/trials.png (per value: the median relative
      width of the interval, (hi - lo) / T, and the coverage and the share of seeds whose best metric is M, with
      their 95 % intervals), titled SIMULATED, and prints a table of them. Deterministic: the same seeds give the
      same file, whatever --jobs (processes, each seed's work its own).

The psychometric function (2AFC, guess 0.5), of intensity I (the metric, floored at 1e-6; for jod_popping the drop
10 - JOD, floored at 1e-4):
    P(I) = 0.5 + (0.5 - lapse) * (1 - exp(-c * (I / threshold)^slope)),  c = -ln(1 - 0.25 / (0.5 - lapse)),
a Weibull with its scale set so that P(threshold) = 0.75 whatever the lapse: `threshold` is the 75 % point, one JND.
The fit is in log10 intensity, threshold (within 1.5 decades of the stimuli shown), slope (0.3 to 30) and lapse (0
to 0.06) free. The 95 % interval is the bootstrap's 2.5 and 97.5 % points of the threshold (percentile interval).
On the synthetic stimuli of the tests it held a planted threshold in 89 of 100 simulated observers with 240 trials
(91 with 1000 resamples) and in 93 % with 360: a little narrower than 95 %, as percentile intervals of small samples
are. The held-out log-likelihood scores each fold's fit with its lapse taken as at least 1 % (HELDOUT_LAPSE_FLOOR):
a fold fitted with lapse 0 predicts certainty far above threshold, and a single lapse of the observer there costs
log(1e-12), which made the best metric a matter of chance (the planted metric won 14 of 20 seeds without the floor,
19 of 20 with it, at 240 trials).

Why scipy (scipy.optimize's SLSQP on a numpy-vectorised likelihood with its analytic gradient): it is maintained and
does the maximum likelihood + bootstrap asked for. psignifit is Bayesian (its intervals are posterior credible
intervals, not a bootstrap of the MLE); questplus is an adaptive procedure that runs in Python, not in the page. The
bootstrap fits start from the full fit (warm start) and the trials are pooled into counts per stimulus, so 1000
resamples of five metrics take a few seconds.
"""
import argparse
import datetime
import json
import math
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from lodbench_results import save_figure  # noqa: E402  (beside this file)

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = ROOT / "src" / "commands" / "calibrate" / "page.html"
PLACEHOLDER = "__LODBENCH_STIMULI__"
STIMULI_FORMAT = "lodbench-calibration-stimuli"
RESPONSES_FORMAT = "lodbench-calibration-responses"

GUESS = 0.5
TARGET = 0.75
LAPSE_BOUNDS = (0.0, 0.06)
SLOPE_BOUNDS = (0.3, 30.0)
FOLDS = 5
# The least lapse with which held-out trials are scored (heldout_ll).
HELDOUT_LAPSE_FLOOR = 0.01
FORM = ("2AFC Weibull in intensity I: P(I) = 0.5 + (0.5 - lapse) * (1 - exp(-c * (I / threshold)^slope)), "
        "c = -ln(1 - 0.25 / (0.5 - lapse)) so that P(threshold) = 0.75; fitted in log10 I")
JOD = "jod_popping"  # intensity = 10 - JOD (its drop from "no visible difference")


class Refusal(Exception):
    """Bad input: one line that names the file and the reason (exit code 2, nothing written)."""


# ----------------------------------------------------------------------------------------------------------------
# Intensities


def intensity(metric: str, value):
    """What the fit sees of a metric's value: jod_popping's drop 10 - JOD (floored at 1e-4), the others as they are
    (floored at 1e-6)."""
    value = np.asarray(value, dtype=float)
    return np.maximum(10.0 - value, 1e-4) if metric == JOD else np.maximum(value, 1e-6)


def to_metric(metric: str, i):
    """An intensity back in the metric's own units (a JOD value for jod_popping)."""
    return 10.0 - i if metric == JOD else i


# ----------------------------------------------------------------------------------------------------------------
# The procedure: mirrors page.html's JavaScript between `// BEGIN procedure` and `// END procedure`. Keep them the
# same: same state (a JSON object), same draws of the PRNG in the same order.

M32 = 0xFFFFFFFF


def mulberry32(s: int):
    """One step of mulberry32: (the new 32-bit state, a float in [0, 1))."""
    s = (s + 0x6D2B79F5) & M32
    t = s
    t = ((t ^ (t >> 15)) * (t | 1)) & M32
    t ^= (t + (((t ^ (t >> 7)) * (t | 61)) & M32)) & M32
    return s, ((t ^ (t >> 14)) & M32) / 4294967296


def procedure_start(stimuli: dict) -> dict:
    """The state before the first trial: every track at the top of its ladder (the largest change), the first trial
    drawn."""
    state = {"rng": int(stimuli["procedure"]["seed"]) & M32,
             "tracks": [{"level": len(t["stimuli"]) - 1, "valid": 0} for t in stimuli["tracks"]],
             "trial": None, "n": 0}
    return draw_trial(stimuli, state)


def draw_trial(stimuli: dict, state: dict) -> dict:
    """The next trial: a track drawn among the unfinished ones, its stimulus at the track's level, the interval that
    holds the switch drawn; trial None when every track is finished."""
    per_track = stimuli["procedure"]["trials_per_track"]
    unfinished = [i for i, t in enumerate(state["tracks"]) if t["valid"] < per_track]
    if not unfinished:
        return {**state, "trial": None}
    rng, u = mulberry32(state["rng"])
    track = unfinished[math.floor(u * len(unfinished))]
    rng, u = mulberry32(rng)
    switch_interval = 1 if u < 0.5 else 2
    level = state["tracks"][track]["level"]
    return {**state, "rng": rng, "trial": {"track": track, "level": level,
                                           "stimulus": stimuli["tracks"][track]["stimuli"][level],
                                           "switch_interval": switch_interval}}


def procedure_next(stimuli: dict, state: dict, outcome: dict) -> dict:
    """The state after the current trial's outcome {valid, correct}. A valid trial moves its track down_steps after
    a correct answer and up up_steps after a wrong one (clamped to the ladder): Kaernbach's weighted up-down, which
    settles where p * down = (1 - p) * up, p = 75 % for 1 down / 3 up. An invalid trial changes nothing of its
    track: the same stimulus comes again when the track is next drawn."""
    p = stimuli["procedure"]
    i = state["trial"]["track"]
    tracks = [dict(t) for t in state["tracks"]]
    if outcome["valid"]:
        t = tracks[i]
        top = len(stimuli["tracks"][i]["stimuli"]) - 1
        t["level"] = min(top, max(0, t["level"] + (-p["down_steps"] if outcome["correct"] else p["up_steps"])))
        t["valid"] += 1
    return draw_trial(stimuli, {**state, "tracks": tracks, "n": state["n"] + 1})


# ----------------------------------------------------------------------------------------------------------------
# The psychometric function and its likelihood


def _c(lapse):
    """c of P(threshold) = 0.75: (0.5 - lapse) * (1 - exp(-c)) = 0.25."""
    return -np.log1p(-0.25 / (0.5 - lapse))


def p_correct(lx, lt, slope, lapse):
    """P(correct) at log10 intensity lx; lt = log10 threshold."""
    z = 10.0 ** np.minimum(slope * (np.asarray(lx) - lt), 300.0)
    return GUESS + (0.5 - lapse) * -np.expm1(-_c(lapse) * z)


def nll(theta, lx, n, k):
    """The negative log-likelihood of counts (k correct of n at log10 intensity lx) and its gradient in theta =
    (log10 threshold, slope, lapse)."""
    lt, slope, lapse = theta
    c = _c(lapse)
    d = lx - lt
    z = 10.0 ** np.minimum(slope * d, 300.0)
    e = np.exp(-c * z)
    h = 0.5 - lapse
    p = np.clip(GUESS + h * (1.0 - e), 1e-12, 1.0)
    q = np.clip(lapse + h * e, 1e-12, 1.0)  # 1 - p without cancellation
    f = -(k * np.log(p) + (n - k) * np.log(q)).sum()
    w = -(k / p - (n - k) / q)  # d nll / d p
    dp_dz = h * e * c
    ln10 = math.log(10.0)
    dc = (1.0 / (1.0 - 0.25 / h)) * 0.25 / h**2
    g = np.array([(w * dp_dz * z * slope * -ln10).sum(),
                  (w * dp_dz * z * ln10 * d).sum(),
                  (w * (-(1.0 - e) + h * e * z * dc)).sum()])
    return f, g


def fit_counts(lx, n, k, starts, bounds):
    """The maximum-likelihood theta from the best of several starting points: (theta, nll). SLSQP with the analytic
    gradient: on these three-parameter problems it needs the fewest evaluations of the bounded methods, and it
    calls no multithreaded BLAS (L-BFGS-B's OpenBLAS threads spin against a busy machine's other work)."""
    from scipy.optimize import minimize

    best = None
    for x0 in starts:
        r = minimize(nll, x0, args=(lx, n, k), jac=True, method="SLSQP", bounds=bounds)
        if best is None or r.fun < best.fun:
            best = r
    return np.clip(best.x, *np.array(bounds).T), float(best.fun)


def heldout_ll(theta, lx, n, k) -> float:
    """The log-likelihood of held-out counts under a fold's fit, its lapse taken as at least HELDOUT_LAPSE_FLOOR: a
    fold fitted with lapse 0 predicts certainty far above threshold, and one lapse of the observer there (log 1e-12)
    would decide the comparison between metrics by chance."""
    lt, slope, lapse = theta
    return -nll((lt, slope, max(lapse, HELDOUT_LAPSE_FLOOR)), lx, n, k)[0]


def fit_metric(lx, trials: "Trials", folds, boot_n, boot_k) -> dict:
    """One metric's fit: the full fit (from a grid of starts), the bootstrap's thresholds (each fit warm-started
    from the full one; None without resamples) and the k-fold held-out log-likelihood. lx: log10 intensity per
    stimulus; only the stimuli shown enter the likelihood."""
    shown = trials.n > 0
    lx = lx[shown]
    lo, hi = float(lx.min()), float(lx.max())
    bounds = [(lo - 1.5, hi + 1.5), SLOPE_BOUNDS, LAPSE_BOUNDS]
    starts = [(lt, s, 0.01) for lt in np.linspace(lo, hi, 5) for s in (1.0, 3.0, 8.0)]
    theta, f = fit_counts(lx, trials.n[shown], trials.k[shown], starts, bounds)
    warm = [tuple(theta)]
    boot = np.array([fit_counts(lx, bn, bk, warm, bounds)[0][0]
                     for bn, bk in zip(boot_n[:, shown], boot_k[:, shown])]) if boot_n is not None else None
    heldout = 0.0
    for fold in range(FOLDS):
        train_n, train_k = trials.counts(folds != fold)
        test_n, test_k = trials.counts(folds == fold)
        t_theta, _ = fit_counts(lx, train_n[shown], train_k[shown], warm + [(lo, 3.0, 0.01), (hi, 3.0, 0.01)],
                                bounds)
        heldout += heldout_ll(t_theta, lx, test_n[shown], test_k[shown])
    return {"theta": theta, "nll": f, "boot_lt": boot, "heldout": heldout}


class Trials:
    """The valid trials pooled: per trial its stimulus (an index into `ids`) and whether it was answered right;
    per stimulus the counts n (trials) and k (correct)."""

    def __init__(self, ids, stim, correct):
        self.ids = ids
        self.stim = np.asarray(stim, dtype=np.int64)
        self.correct = np.asarray(correct, dtype=float)
        self.n, self.k = self.counts(np.ones(len(self.stim), dtype=bool))

    def counts(self, mask):
        m = len(self.ids)
        return (np.bincount(self.stim[mask], minlength=m).astype(float),
                np.bincount(self.stim[mask], weights=self.correct[mask], minlength=m))


# ----------------------------------------------------------------------------------------------------------------
# Input


def read_json(path: Path, fmt: str) -> dict:
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as e:
        raise Refusal(f"{path}: cannot read ({e.strerror})") from None
    except UnicodeDecodeError:
        raise Refusal(f"{path}: not UTF-8 text") from None
    if not text.strip():
        raise Refusal(f"{path}: empty file")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise Refusal(f"{path}: malformed JSON ({e.msg} at line {e.lineno} column {e.colno})") from None
    if not isinstance(data, dict) or data.get("format") != fmt:
        got = data.get("format") if isinstance(data, dict) else type(data).__name__
        raise Refusal(f"{path}: not a {fmt} file (format {got!r})")
    if data.get("version") != 1:
        raise Refusal(f"{path}: {fmt} version {data.get('version')!r}, this script reads version 1")
    return data


def read_stimuli(path: Path) -> dict:
    s = read_json(path, STIMULI_FORMAT)
    for key in ("id", "display", "stimulus", "procedure", "metrics", "tracks", "stimuli"):
        if key not in s:
            raise Refusal(f"{path}: no {key!r}")
    if s["procedure"].get("kind") != "weighted-up-down":
        raise Refusal(f"{path}: procedure {s['procedure'].get('kind')!r}, this script knows weighted-up-down")
    ids = {st["id"] for st in s["stimuli"]}
    for t in s["tracks"]:
        if not t["stimuli"]:
            raise Refusal(f"{path}: track {t['id']} has no stimuli")
        for sid in t["stimuli"]:
            if sid not in ids:
                raise Refusal(f"{path}: track {t['id']} names stimulus {sid}, which is not in stimuli")
    for st in s["stimuli"]:
        for m in s["metrics"]:
            v = st.get(m)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
                raise Refusal(f"{path}: stimulus {st['id']} has no number for metric {m!r}")
    return s


def check_metrics(names, stimuli: dict, path) -> list:
    for m in names:
        if m not in stimuli["metrics"]:
            raise Refusal(f"{path}: unknown metric {m!r} (its metrics: {', '.join(stimuli['metrics'])})")
    return list(names)


def first_difference(a: dict, b: dict) -> str:
    for key in sorted(set(a) | set(b)):
        if a.get(key) != b.get(key):
            return f"{key} {a.get(key)!r} vs {b.get(key)!r}"
    return "?"


def read_responses(path: Path, stimuli: dict, stimuli_path: Path) -> dict:
    r = read_json(path, RESPONSES_FORMAT)
    if not isinstance(r.get("display"), dict) or r["display"] != stimuli["display"]:
        raise Refusal(f"{path}: made on another display than {stimuli_path}'s "
                      f"({first_difference(r.get('display') or {}, stimuli['display'])})")
    if r.get("stimuli_id") != stimuli["id"]:
        raise Refusal(f"{path}: responses to stimuli {r.get('stimuli_id')!r}, not to {stimuli_path} "
                      f"({stimuli['id']})")
    trials = r.get("trials")
    if not isinstance(trials, list):
        raise Refusal(f"{path}: no trials list")
    known = {st["id"] for st in stimuli["stimuli"]}
    for t in trials:
        if t.get("stimulus") not in known:
            raise Refusal(f"{path}: trial {t.get('n')} shows stimulus {t.get('stimulus')!r}, not in {stimuli_path}")
        if t.get("valid") and not isinstance(t.get("correct"), bool):
            raise Refusal(f"{path}: valid trial {t.get('n')} has no correct true/false")
    if not any(t.get("valid") for t in trials):
        raise Refusal(f"{path}: no valid trials")
    return r


# ----------------------------------------------------------------------------------------------------------------
# The fit


def describe_simulation(sim: dict) -> str:
    return (f"planted on {sim['metric']}, threshold {sim['threshold']:g}, slope {sim['slope']:g}, "
            f"lapse {sim['lapse']:g}")


def fit(stimuli: dict, responses: list, bootstrap=1000, seed=1, metrics=None, bootstrap_metrics=None) -> dict:
    """calibration.json's content (and, under "_curves", what the figures draw) from the stimuli and the response
    files (already checked). bootstrap_metrics: the metrics whose interval is bootstrapped (default all; the others
    get ci95 [None, None]), for tests that need one metric's interval."""
    import scipy

    metrics = list(metrics or stimuli["metrics"])
    ids = [st["id"] for st in stimuli["stimuli"]]
    index = {sid: i for i, sid in enumerate(ids)}
    valid = [t for r in responses for t in r["trials"] if t.get("valid")]
    trials = Trials(ids, [index[t["stimulus"]] for t in valid], [bool(t["correct"]) for t in valid])
    n_trials = len(valid)
    # Folds: a seeded random split of the trials, the same for every metric (their held-out likelihoods compare).
    rng_folds = np.random.default_rng([seed, 0])
    folds = np.empty(n_trials, dtype=np.int64)
    folds[rng_folds.permutation(n_trials)] = np.arange(n_trials) % FOLDS
    # Bootstrap: trials drawn with replacement = a multinomial over the cells (stimulus, right / wrong); the same
    # resamples for every metric.
    rng_boot = np.random.default_rng([seed, 1])
    cells = np.concatenate([trials.k, trials.n - trials.k]) / n_trials
    draws = rng_boot.multinomial(n_trials, cells, size=bootstrap) if bootstrap else np.zeros((0, 2 * len(ids)))
    boot_k = draws[:, :len(ids)].astype(float)
    boot_n = boot_k + draws[:, len(ids):]
    by_id = {st["id"]: st for st in stimuli["stimuli"]}
    out_metrics, curves = {}, {}
    for m in metrics:
        lx = np.log10(intensity(m, [by_id[sid][m] for sid in ids]))
        boot = bootstrap and (bootstrap_metrics is None or m in bootstrap_metrics)
        r = fit_metric(lx, trials, folds, boot_n if boot else None, boot_k if boot else None)
        lt, slope, lapse = (float(v) for v in r["theta"])
        thr = 10.0**lt
        if boot:
            ci = 10.0 ** np.percentile(r["boot_lt"], [2.5, 97.5])
            ci = sorted(float(to_metric(m, v)) for v in ci)
        else:
            ci = [None, None]
        out_metrics[m] = {"threshold": float(to_metric(m, thr)), "ci95": ci, "slope": slope, "lapse": lapse,
                          "log_likelihood": -r["nll"], "heldout_log_likelihood": float(r["heldout"]),
                          "n_trials": n_trials}
        curves[m] = {"lx": lx, "n": trials.n, "k": trials.k, "theta": r["theta"]}
    best = max(metrics, key=lambda m: out_metrics[m]["heldout_log_likelihood"])
    simulated = [r for r in responses if r.get("simulated")]
    observers = list(dict.fromkeys(str(r.get("observer")) for r in responses))
    if simulated:
        plants = list(dict.fromkeys(describe_simulation(r["simulation"]) for r in simulated if r.get("simulation")))
        label = f"SIMULATED observer ({'; '.join(plants) or 'unknown plant'}): not human data"
    else:
        label = (f"{len(observers)} observer{'s' if len(observers) != 1 else ''}, "
                 f"{n_trials} trial{'s' if n_trials != 1 else ''}")
    return {"format": "lodbench-calibration", "version": 1, "simulated": bool(simulated), "label": label,
            "display": stimuli["display"], "stimuli_id": stimuli["id"], "trials": n_trials, "observers": observers,
            "best_metric": best, "metrics": out_metrics,
            "psychometric": {"form": FORM, "guess": GUESS, "lapse_bounds": list(LAPSE_BOUNDS), "target": TARGET},
            "fit": {"package": f"scipy {scipy.__version__}", "bootstrap": bootstrap, "folds": FOLDS, "seed": seed},
            "_curves": curves}


def table(cal: dict) -> str:
    rows = [f"{cal['label']}; best metric (held-out log-likelihood): {cal['best_metric']}",
            f"{'metric':<16} {'threshold':>10} {'95 % interval':>24} {'slope':>6} {'lapse':>6} {'logL':>9} "
            f"{'held-out':>9}"]
    for m, r in cal["metrics"].items():
        lo, hi = r["ci95"]
        ci = f"[{lo:.4g}, {hi:.4g}]" if lo is not None else "-"
        mark = " *" if m == cal["best_metric"] else ""
        rows.append(f"{m:<16} {r['threshold']:>10.4g} {ci:>24} {r['slope']:>6.2f} {r['lapse']:>6.3f} "
                    f"{r['log_likelihood']:>9.1f} {r['heldout_log_likelihood']:>9.1f}{mark}")
    return "\n".join(rows)


def figure(cal: dict, metric: str, path: Path):
    """Proportion correct per stimulus (marker area ~ its trials) against intensity, the fitted curve, the threshold
    and its 95 % interval."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c = cal["_curves"][metric]
    r = cal["metrics"][metric]
    shown = c["n"] > 0
    x = 10.0 ** c["lx"][shown]
    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=110)
    ax.scatter(x, c["k"][shown] / c["n"][shown], s=6 + 6 * c["n"][shown], alpha=0.45, color="tab:blue",
               edgecolors="none", label="stimuli (area ~ trials)")
    span = np.linspace(c["lx"].min() - 0.3, c["lx"].max() + 0.3, 300)
    ax.plot(10.0**span, p_correct(span, *c["theta"]), color="black", label="fit")
    thr = 10.0 ** c["theta"][0]
    lo, hi = r["ci95"]
    if lo is not None:
        a, b = sorted(float(intensity(metric, v)) for v in (lo, hi))
        ax.axvspan(a, b, color="tab:orange", alpha=0.2, label="95 % interval")
    unit = f" JOD (drop {thr:.4g})" if metric == JOD else ""
    ax.axvline(thr, color="tab:orange", label=f"75 % threshold {r['threshold']:.4g}{unit}")
    ax.axhline(TARGET, color="grey", lw=0.8, ls=":")
    ax.set_xscale("log")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlabel("10 - jod_popping (drop from 10 JOD)" if metric == JOD else metric)
    ax.set_ylabel("proportion correct (2AFC)")
    title = f"{metric}: {r['n_trials']} trials, held-out logL {r['heldout_log_likelihood']:.1f}"
    if metric == cal["best_metric"]:
        title += " (best)"
    if cal["simulated"]:
        title = "SIMULATED: " + title
    ax.set_title(title, fontsize=10, color="darkred" if cal["simulated"] else "black")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    write_atomic(path, lambda f: save_figure(fig, f))
    plt.close(fig)


def write_atomic(path: Path, write):
    """Writes `path` through a temporary file in its folder, then renames it: never half-written."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 otherwise
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_json(path: Path, data):
    write_atomic(path, lambda f: f.write((json.dumps(data, indent=2) + "\n").encode()))


# ----------------------------------------------------------------------------------------------------------------
# The simulated observer


def simulate(stimuli: dict, metric: str, threshold: float, slope: float, lapse: float, seed: int,
             trials_per_track=None) -> dict:
    """responses.json of a simulated observer that answers with P(correct) = p_correct(intensity of `metric`) through
    the page's procedure. The procedure's draws come from procedure.seed as on the page; the observer's from `seed`."""
    if trials_per_track is not None:
        stimuli = {**stimuli, "procedure": {**stimuli["procedure"], "trials_per_track": trials_per_track}}
    lt = math.log10(float(intensity(metric, threshold)))
    by_id = {st["id"]: st for st in stimuli["stimuli"]}
    rng = np.random.default_rng(seed)
    state = procedure_start(stimuli)
    trials = []
    while state["trial"] is not None:
        t = state["trial"]
        lx = math.log10(float(intensity(metric, by_id[t["stimulus"]][metric])))
        correct = bool(rng.random() < p_correct(lx, lt, slope, lapse))
        response = t["switch_interval"] if correct else 3 - t["switch_interval"]
        trials.append({"n": state["n"], "track": stimuli["tracks"][t["track"]]["id"], "stimulus": t["stimulus"],
                       "switch_interval": t["switch_interval"], "response": response, "correct": correct,
                       "rt_ms": None, "valid": True, "invalid_reason": None, "frame_intervals_ms": []})
        state = procedure_next(stimuli, state, {"valid": True, "correct": correct})
    return {"format": RESPONSES_FORMAT, "version": 1, "stimuli_id": stimuli["id"], "display": stimuli["display"],
            "observer": "simulated", "simulated": True,
            "simulation": {"metric": metric, "threshold": threshold, "slope": slope, "lapse": lapse, "seed": seed},
            "user_agent": "scripts/calibration.py simulate", "measured_refresh_hz": None,
            "started": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "trials": trials}


# ----------------------------------------------------------------------------------------------------------------
# How many trials: the simulation study of `trials`

TRIALS_COLUMNS = ("trials_per_track", "seed", "total_trials", "threshold", "ci_lo", "ci_hi", "covered",
                  "best_metric")


def trials_row(stimuli: dict, metric: str, threshold: float, slope: float, lapse: float, bootstrap: int,
               task) -> dict:
    """One row of trials.csv: the observer of seed `seed` at `trials_per_track` (task = (trials_per_track, seed)),
    simulated and fitted (every metric, for the best one; the bootstrap interval of `metric` only)."""
    trials_per_track, seed = task
    r = simulate(stimuli, metric, threshold, slope, lapse, seed, trials_per_track)
    cal = fit(stimuli, [r], bootstrap=bootstrap, seed=seed, bootstrap_metrics=[metric])
    f = cal["metrics"][metric]
    lo, hi = f["ci95"]
    return {"trials_per_track": trials_per_track, "seed": seed, "total_trials": cal["trials"],
            "threshold": f["threshold"], "ci_lo": lo, "ci_hi": hi, "covered": bool(lo <= threshold <= hi),
            "best_metric": cal["best_metric"]}


def trials_study(stimuli: dict, metric: str, threshold: float, slope: float, lapse: float, trials, seeds,
                 bootstrap: int, jobs: int = 1) -> list:
    """trials.csv's rows, ordered by trials per track then seed. `jobs` > 1 spreads the rows over processes; each
    row depends on its own seed alone, so the rows are the same whatever `jobs`."""
    import functools

    tasks = [(n, seed) for n in trials for seed in seeds]
    one = functools.partial(trials_row, stimuli, metric, threshold, slope, lapse, bootstrap)
    if jobs <= 1:
        return [one(t) for t in tasks]
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(one, tasks, chunksize=max(1, len(tasks) // (4 * jobs))))


def wilson(k: int, n: int):
    """The Wilson 95 % interval of a proportion k / n."""
    if n == 0:
        return float("nan"), float("nan")
    z = 1.959964
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def trials_summary(rows, metric: str, threshold: float) -> list:
    """Per trials-per-track value: its total trials, the coverage (k of n seeds whose interval holds the planted
    threshold), the interval's median relative width (hi - lo) / T and its quartiles, the median factor hi / lo
    (both in the metric's intensity: for jod_popping the drops from 10), the median fitted threshold over T, and
    the share of seeds whose best metric is `metric`."""
    t = float(intensity(metric, threshold))
    out = []
    for n in dict.fromkeys(r["trials_per_track"] for r in rows):
        mine = [r for r in rows if r["trials_per_track"] == n]
        lo = intensity(metric, [r["ci_lo"] for r in mine])
        hi = intensity(metric, [r["ci_hi"] for r in mine])
        lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
        rel = (hi - lo) / t
        covered = sum(r["covered"] for r in mine)
        best = sum(r["best_metric"] == metric for r in mine)
        out.append({"trials_per_track": n, "total_trials": sorted({r["total_trials"] for r in mine}),
                    "seeds": len(mine), "covered": covered, "coverage": covered / len(mine),
                    "coverage_ci": wilson(covered, len(mine)), "width": float(np.median(rel)),
                    "width_q": (float(np.percentile(rel, 25)), float(np.percentile(rel, 75))),
                    "factor": float(np.median(hi / lo)),
                    "bias": float(np.median(intensity(metric, [r["threshold"] for r in mine]) / t)),
                    "best": best, "best_share": best / len(mine), "best_ci": wilson(best, len(mine))})
    return out


def trials_table(summary, metric: str, plant: str) -> str:
    rows = [f"SIMULATED observers ({plant}); per trials-per-track value {summary[0]['seeds']} seeds",
            f"{'trials/track':>12} {'total':>7} {'coverage':>16} {'width (hi-lo)/T':>16} {'hi/lo':>6} "
            f"{'thr/T':>6} {'best = ' + metric:>22}"]
    for r in summary:
        total = "/".join(str(v) for v in r["total_trials"])
        cov = f"{r['covered']}/{r['seeds']} {100 * r['coverage']:3.0f} %"
        best = f"{r['best']}/{r['seeds']} {100 * r['best_share']:3.0f} %"
        rows.append(f"{r['trials_per_track']:>12} {total:>7} {cov:>16} {r['width']:>16.3f} {r['factor']:>6.2f} "
                    f"{r['bias']:>6.3f} {best:>22}")
    return "\n".join(rows)


def trials_figure(summary, metric: str, plant: str, bootstrap: int, path: Path):
    """The interval's median relative width (quartiles as a band) and, beside it, the coverage and the share of
    seeds whose best metric is `metric` (Wilson 95 % intervals), against trials per track."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.array([r["trials_per_track"] for r in summary], dtype=float)
    fig, (a, b) = plt.subplots(1, 2, figsize=(10.5, 4.2), dpi=110)
    w = np.array([r["width"] for r in summary])
    q = np.array([r["width_q"] for r in summary])
    a.fill_between(x, q[:, 0], q[:, 1], color="tab:blue", alpha=0.2, label="quartiles")
    a.plot(x, w, "o-", color="tab:blue", label="median")
    a.set_ylim(0, None)
    a.set_xlabel("trials per track")
    a.set_ylabel(f"95 % interval width (hi - lo) / threshold ({metric})")
    a.legend(fontsize=8)
    a.grid(alpha=0.3)
    step = 0.01 * (x.max() - x.min() or 1.0)  # the two series side by side, their bars apart
    for key, ci, colour, label, dx in (
            ("coverage", "coverage_ci", "tab:orange", "coverage of the planted threshold", -step),
            ("best_share", "best_ci", "tab:green", f"best metric is {metric}", step)):
        y = np.array([r[key] for r in summary])
        e = np.array([r[ci] for r in summary])
        yerr = np.maximum(0.0, [y - e[:, 0], e[:, 1] - y])  # >= 0: Wilson's ends at 0 and 1 round
        b.errorbar(x + dx, y, yerr=yerr, fmt="o-", color=colour, capsize=3, label=label)
    b.axhline(0.95, color="grey", ls="--", lw=0.8, label="nominal 95 %")
    b.set_ylim(0, 1.02)
    b.set_xlabel("trials per track")
    b.set_ylabel(f"share of seeds (of {summary[0]['seeds']}; Wilson 95 %)")
    b.legend(fontsize=8, loc="lower right")
    b.grid(alpha=0.3)
    for ax in (a, b):
        ax.set_xticks(x)
        ax.set_xticklabels([f"{r['trials_per_track']}\n({'/'.join(map(str, r['total_trials']))})" for r in summary],
                           fontsize=8)
    fig.suptitle(f"SIMULATED observers, not human data: {plant}; {summary[0]['seeds']} seeds per point, "
                 f"{bootstrap} resamples (x: trials per track (total))", fontsize=9, color="darkred")
    fig.tight_layout()
    write_atomic(path, lambda f: save_figure(fig, f))
    plt.close(fig)


def write_trials_csv(path: Path, rows):
    import csv
    import io

    buf = io.StringIO()
    w = csv.DictWriter(buf, TRIALS_COLUMNS, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({**r, "threshold": repr(r["threshold"]), "ci_lo": repr(r["ci_lo"]), "ci_hi": repr(r["ci_hi"]),
                    "covered": str(r["covered"]).lower()})
    write_atomic(path, lambda f: f.write(buf.getvalue().encode()))


def positive_ints(text: str, flag: str) -> list:
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise Refusal(f"{flag} {text!r}: not a comma-separated list of whole numbers") from None
    if not values or any(v < 1 for v in values) or len(set(values)) != len(values):
        raise Refusal(f"{flag} {text!r}: needs distinct whole numbers >= 1")
    return values


# ----------------------------------------------------------------------------------------------------------------
# The page


def page(stimuli: dict, template: Path = TEMPLATE) -> str:
    """The page as `lodbench calibrate` writes it: the placeholder replaced by the compact stimuli JSON with every
    `</` written `<\\/`."""
    html = template.read_text(encoding="utf-8")
    if html.count(PLACEHOLDER) != 1:
        raise Refusal(f"{template}: the placeholder {PLACEHOLDER} appears {html.count(PLACEHOLDER)} times, not once")
    data = json.dumps(stimuli, separators=(",", ":"), ensure_ascii=False).replace("</", "<\\/")
    return html.replace(PLACEHOLDER, data)


# ----------------------------------------------------------------------------------------------------------------
# Command line


def check_plant(args, stimuli: dict):
    """simulate's and trials' planted observer: a metric of stimuli.json, a lapse below 25 %, a slope above 0, a
    threshold above 0 (for jod_popping below 10 JOD)."""
    check_metrics([args.metric], stimuli, args.stimuli)
    if not 0 <= args.lapse < 0.25:
        raise Refusal(f"--lapse {args.lapse}: must be in [0, 0.25) (P(correct) must reach 75 %)")
    if args.slope <= 0 or (args.metric != JOD and args.threshold <= 0) or (
            args.metric == JOD and args.threshold >= 10):
        raise Refusal("--slope must be > 0 and --threshold > 0 (for jod_popping < 10 JOD)")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("page", help="write the experiment page for a stimuli.json")
    p.add_argument("stimuli", type=Path)
    p.add_argument("--out", type=Path, required=True)
    s = sub.add_parser("simulate", help="a simulated observer's responses.json")
    s.add_argument("stimuli", type=Path)
    s.add_argument("--metric", required=True)
    s.add_argument("--threshold", type=float, required=True, help="75 %% point in the metric's units (JOD for "
                   "jod_popping)")
    s.add_argument("--slope", type=float, required=True)
    s.add_argument("--lapse", type=float, default=0.02)
    s.add_argument("--seed", type=int, required=True)
    s.add_argument("--trials-per-track", type=int)
    s.add_argument("--out", type=Path, required=True)
    f = sub.add_parser("fit", help="fit the psychometric function of every metric")
    f.add_argument("stimuli", type=Path)
    f.add_argument("responses", type=Path, nargs="+")
    f.add_argument("--out", type=Path, required=True, help="folder of calibration.json and fit-<metric>.png")
    f.add_argument("--bootstrap", type=int, default=1000)
    f.add_argument("--seed", type=int, default=1)
    f.add_argument("--metric", help="comma-separated metrics to fit (default: every metric of stimuli.json)")
    t = sub.add_parser("trials", help="how many trials a threshold needs: simulated observers fitted, per "
                       "trials-per-track value and seed")
    t.add_argument("stimuli", type=Path)
    t.add_argument("--metric", required=True)
    t.add_argument("--threshold", type=float, required=True, help="the planted 75 %% point (JOD for jod_popping)")
    t.add_argument("--slope", type=float, required=True)
    t.add_argument("--lapse", type=float, default=0.02)
    t.add_argument("--trials", default="20,40,60,80", help="trials per track, comma-separated")
    t.add_argument("--seeds", type=int, default=40, help="observers per value: seeds 0..N-1")
    t.add_argument("--bootstrap", type=int, default=200)
    t.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="processes (the rows do not depend on it)")
    t.add_argument("--out", type=Path, required=True, help="folder of trials.csv and trials.png")
    args = ap.parse_args(argv)
    try:
        stimuli = read_stimuli(args.stimuli)
        if args.command == "page":
            html = page(stimuli)
            args.out.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(args.out, lambda fh: fh.write(html.encode()))
            print(f"wrote {args.out}")
        elif args.command == "simulate":
            check_plant(args, stimuli)
            if args.trials_per_track is not None and args.trials_per_track < 1:
                raise Refusal(f"--trials-per-track {args.trials_per_track}: must be >= 1")
            r = simulate(stimuli, args.metric, args.threshold, args.slope, args.lapse, args.seed,
                         args.trials_per_track)
            args.out.parent.mkdir(parents=True, exist_ok=True)
            write_json(args.out, r)
            print(f"wrote {args.out}: {len(r['trials'])} simulated trials, "
                  f"{sum(t['correct'] for t in r['trials'])} correct")
        elif args.command == "trials":
            check_plant(args, stimuli)
            trials = positive_ints(args.trials, "--trials")
            if args.seeds < 1:
                raise Refusal(f"--seeds {args.seeds}: needs at least 1")
            if args.bootstrap < 20:
                raise Refusal(f"--bootstrap {args.bootstrap}: needs at least 20 resamples for a 95 % interval")
            rows = trials_study(stimuli, args.metric, args.threshold, args.slope, args.lapse, trials,
                                range(args.seeds), args.bootstrap, jobs=max(1, args.jobs))
            plant = describe_simulation({"metric": args.metric, "threshold": args.threshold, "slope": args.slope,
                                         "lapse": args.lapse})
            summary = trials_summary(rows, args.metric, args.threshold)
            args.out.mkdir(parents=True, exist_ok=True)
            write_trials_csv(args.out / "trials.csv", rows)
            trials_figure(summary, args.metric, plant, args.bootstrap, args.out / "trials.png")
            print(trials_table(summary, args.metric, plant))
            print(f"wrote {args.out / 'trials.csv'} ({len(rows)} rows) and {args.out / 'trials.png'}")
        else:
            metrics = check_metrics(args.metric.split(","), stimuli, args.stimuli) if args.metric else None
            if args.bootstrap < 20:
                raise Refusal(f"--bootstrap {args.bootstrap}: needs at least 20 resamples for a 95 % interval")
            responses = [read_responses(path, stimuli, args.stimuli) for path in args.responses]
            cal = fit(stimuli, responses, bootstrap=args.bootstrap, seed=args.seed, metrics=metrics)
            args.out.mkdir(parents=True, exist_ok=True)
            for m in cal["metrics"]:
                figure(cal, m, args.out / f"fit-{m}.png")
            curves = cal.pop("_curves")
            del curves
            write_json(args.out / "calibration.json", cal)
            print(table(cal))
            print(f"wrote {args.out / 'calibration.json'} and {len(cal['metrics'])} figures")
    except Refusal as e:
        print(f"calibration.py {args.command}: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
