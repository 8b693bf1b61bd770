"""The papers' experiments on this machine's GPU, in one command (docs/cluster.md, "The GPU suite"); run it as
`scripts/gpu-suite.sh [--budget-s S] [--out ROOT] [--software] [FRAMES [EXPERIMENT ...]]`.

The steps, in the order of what each result settles: lodbench probe (the adapter's ceilings, which the sizing
reads), lodbench overhead (the harness against a bare draw), the A/A check at the paper's size (aa-gpu, then
scripts/aa_check.py), FSI's Fig. 8 viewports, Sheliemietiev's Fig. 5, then Fig. 6, trees-sorting, unified-lod,
terrain-equal-error (with scripts/equal_error.py, then again without the GPU clock's warm-up and
scripts/clock_drops.py) and the frontier. EXPERIMENTs named (file names without .toml) keep only those of the
experiments; the probe and the overhead always run. Each experiment runs at the papers' scenes, counts and
viewports with FRAMES timed frames (default 150) and 10 warm-up frames a block into ROOT/<adapter>/<experiment>/
(ROOT: results/gpu), and is plotted; times.txt gets each step's wall time, and the claims that need a GPU are
printed at the end.

With --budget-s S the suite ends within S seconds of its start, plus at most the frame in progress:
- after the probe, each step's frames are sized from the probe's triangle and blended-fill rates by a cost model
  (`cost`: per block, every method renders one timing frame and, with the quality pass, three more at the
  reference's triangles and the viewport's pixels, plus the block's set-up, measured as `lodbench describe`'s time
  to build its scene), scaled by what the finished steps took against their estimate (`Budget.factor`);
- the steps go in order, each with as many frames as fit in what is left, at most FRAMES; a step that does not fit
  at MIN_FRAMES is left and the next one is tried;
- at the deadline the step in progress gets SIGTERM (lodbench stops after the frame in progress and says
  interrupted in run.json, resumable with `lodbench experiment FILE --resume`) and the suite stops;
- times.txt and budget.json say what ran, at how many frames, what was cut and what was left.
--software runs on a software adapter (lavapipe), to test the budget logic; without it a software adapter is
refused before anything runs. LODBENCH names a lodbench binary to use instead of building one.
"""
import argparse
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from lodbench_results import PROBE_CSV, read_csv  # noqa: E402  (beside this file)

ROOT = Path(__file__).resolve().parents[1]
EXPERIMENTS = ["aa-gpu", "fsi-fig8", "sheliemietiev-fig5", "sheliemietiev-fig6", "trees-sorting", "unified-lod",
               "terrain-equal-error", "frontier"]
WARMUP = 10
# The fewest timed frames a sized step may get: every camera path is walked in full over the timed frames, and below
# this the blocks' transitions crowd into a few frames each.
MIN_FRAMES = 20
# What the quality pass draws per timed frame and method, at most: the reference, the method, lodpop's counterfactual.
QUALITY_FRAMES = 3
# Seconds a step may run past the deadline after its SIGTERM (the frame in progress, run.json written) before SIGKILL.
GRACE_S = 60
OVERHEAD_CONTENDERS = 5


class Refused(Exception):
    """A bad argument or an adapter the suite cannot use: one line, exit 2."""


def log(out: Path, line: str):
    print(line, flush=True)
    with open(out / "times.txt", "a") as f:
        f.write(line + "\n")


# ---------------------------------------------------------------- the cost model


def cost(blocks, frames: int, tri_rate: float, px_rate: float) -> float:
    """Seconds a step of `blocks` takes at `frames` timed frames (plus WARMUP a block), before the correction factor:
    each block is (set-up seconds, methods, frames drawn per frame index and method, triangles, pixels)."""
    s = 0.0
    for setup_s, methods, passes, triangles, pixels in blocks:
        per_frame = methods * passes * (triangles / tri_rate + pixels / px_rate)
        s += setup_s + (frames + WARMUP) * per_frame
    return s


def frames_that_fit(blocks, seconds: float, tri_rate: float, px_rate: float, factor: float, most: int) -> int:
    """The most timed frames (at most `most`) whose estimate, times `factor`, fits in `seconds`; 0 when not even
    MIN_FRAMES do."""
    fixed = cost(blocks, -WARMUP, tri_rate, px_rate)
    per = cost(blocks, 1 - WARMUP, tri_rate, px_rate) - fixed
    if per <= 0:
        return most
    n = math.floor((seconds / factor - fixed) / per) - WARMUP
    n = min(most, n)
    return n if n >= MIN_FRAMES else 0


class Budget:
    """The deadline and what the finished steps taught about the estimates."""

    def __init__(self, seconds, start):
        self.seconds, self.start = seconds, start
        self.ratios = []

    def left(self) -> float:
        return self.start + self.seconds - time.monotonic()

    def factor(self) -> float:
        """The median of the finished steps' measured over estimated time (1 before any)."""
        if not self.ratios:
            return 1.0
        r = sorted(self.ratios)
        mid = len(r) // 2
        return r[mid] if len(r) % 2 else (r[mid - 1] + r[mid]) / 2


# ---------------------------------------------------------------- reading the steps' sizes


def read_toml(path: Path):
    try:
        import tomllib
    except ImportError:  # Python before 3.11
        try:
            import tomli as tomllib
        except ImportError:
            raise Refused("--budget-s reads the experiment files with Python 3.11's tomllib (or the tomli "
                          "package): neither is here") from None
    with open(path, "rb") as f:
        return tomllib.load(f)


class Scenes:
    """LOD0 triangles, viewport and set-up time of (scene, profile, count), from `lodbench describe --json`, cached."""

    def __init__(self, lodbench):
        self.lodbench, self.cache = lodbench, {}

    def get(self, scene, profile, count):
        key = (scene, profile, count)
        if key not in self.cache:
            cmd = [self.lodbench, "describe", "--scene", scene, "--profile", profile, "--json"]
            if count is not None:
                cmd += ["--count", str(count)]
            t0 = time.monotonic()
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0:
                raise Refused(f"lodbench describe --scene {scene} failed: {r.stderr.strip()}")
            d = json.loads(r.stdout)
            counts = d.get("instance_counts") or [1]
            triangles = sum(m["lods"][0]["triangles"] * (counts[i] if i < len(counts) else 1)
                            for i, m in enumerate(d["models"]))
            self.cache[key] = (triangles, (d["width"], d["height"]), time.monotonic() - t0)
        return self.cache[key]


def listed_methods(lodbench, file: Path):
    """Per run of the experiment file, per scene, how many methods it draws (`lodbench experiment --list`)."""
    r = subprocess.run([lodbench, "experiment", str(file), "--list"], capture_output=True, text=True)
    if r.returncode != 0:
        raise Refused(r.stderr.strip())
    runs = []
    for line in r.stdout.splitlines()[1:]:
        body = re.sub(r"^\s*(-\s+|(\S+=\S+\s+)*)shard \d+/\d+\s+", "", line)
        scenes = {}
        for part in body.split("; "):
            scene, _, methods = part.partition(": ")
            scenes[scene.strip()] = len(methods.split(", "))
        runs.append(scenes)
    return runs


def experiment_blocks(lodbench, scenes: Scenes, name: str):
    """The blocks of experiment `name` for `cost` (each run's scenes and counts, with their methods)."""
    file = ROOT / "scenes" / "experiments" / f"{name}.toml"
    spec = read_toml(file)
    run = spec.get("run", {})
    sweep = spec.get("sweep", {})
    variables = sweep.get("variables") or ([sweep["variable"]] if "variable" in sweep else [])
    values = sweep.get("values") or [None]
    methods = listed_methods(lodbench, file)
    profile = run.get("profile", "ci")
    passes = 1 if run.get("quality") == "off" else 1 + QUALITY_FRAMES
    blocks = []
    for i, value in enumerate(values if variables else [None]):
        size = (run.get("width"), run.get("height"))
        if variables == ["viewport"] and value is not None:
            size = tuple(value)
        counts = run.get("count")
        counts = counts if isinstance(counts, list) else [counts]
        for scene, n_methods in (methods[i] if i < len(methods) else methods[-1]).items():
            for count in counts:
                triangles, default_size, setup_s = scenes.get(scene, profile, count)
                w, h = (size[0] or default_size[0], size[1] or default_size[1])
                blocks.append((setup_s, n_methods, passes, triangles, w * h))
    return blocks


def overhead_blocks(scenes: Scenes):
    out = []
    for scene, count in (("bunny-grid", 50), ("bunny-grid", 500), ("bunny-grid", 2000), ("trees", 400)):
        triangles, (w, h), setup_s = scenes.get(scene, "paper", count)
        out.append((setup_s, OVERHEAD_CONTENDERS, 1, triangles, w * h))
    return out


def probe_rates(folder: Path):
    """(triangles a second, blended fragments a second) from the probe's probe.csv: the slower of the plain and the
    instanced triangle rates."""
    rows = {r["probe"]: float(r["rate_median"]) for r in read_csv(folder / PROBE_CSV)}
    return min(rows["triangles"], rows["triangles-instanced"]), rows["fill-blended"]


# ---------------------------------------------------------------- running


class Suite:
    def __init__(self, args, lodbench, out: Path):
        self.args, self.lodbench, self.out = args, lodbench, out
        self.budget = Budget(args.budget_s, time.monotonic()) if args.budget_s else None
        self.steps = []  # budget.json's entries
        self.child = None
        self.stopped = False

    def run(self, cmd, tee=None) -> str:
        """Runs `cmd` (a list) to its end, or, with a budget, to the deadline: then SIGTERM, and GRACE_S later
        SIGKILL. With `tee`, its output goes to that file and is printed once it ends. Returns "ran", "cut" or
        "failed"."""
        out = open(tee, "w") if tee else None
        self.child = subprocess.Popen(cmd, stdout=out, text=True)
        cut = False
        while self.child.poll() is None:
            if self.stopped or (self.budget and self.budget.left() <= 0):
                cut = True
                self.child.send_signal(signal.SIGTERM)
                try:
                    self.child.wait(GRACE_S)
                except subprocess.TimeoutExpired:
                    self.child.kill()
                    self.child.wait()
                break
            time.sleep(0.2)
        code = self.child.returncode
        self.child = None
        if out:
            out.close()
            sys.stdout.write(Path(tee).read_text())
        return "cut" if cut else ("ran" if code == 0 else "failed")

    def step(self, name, commands, blocks=None, most=None):
        """One step: its commands in order (each a list, or a (list, tee file)). With a budget and `blocks`, its
        frames are sized first; a callable command gets the frames. Returns whether it finished."""
        entry = {"step": name}
        self.steps.append(entry)
        frames = most
        estimate = None
        if self.budget and blocks is not None:
            left = self.budget.left()
            tri, px = self.rates
            frames = frames_that_fit(blocks, left, tri, px, self.budget.factor(), most)
            need = self.budget.factor() * cost(blocks, MIN_FRAMES, tri, px)
            if frames == 0 or self.stopped:
                entry.update(status="left", needs_s=round(need, 1), left_s=round(max(left, 0), 1))
                log(self.out, f"{name}: left (about {need:.0f} s at {MIN_FRAMES} frames; {max(left, 0):.0f} s were "
                              "left)")
                return False
            estimate = self.budget.factor() * cost(blocks, frames, tri, px)
            entry["estimate_s"] = round(estimate, 1)
        elif self.budget and (self.stopped or self.budget.left() <= 0):
            entry.update(status="left", left_s=0)
            log(self.out, f"{name}: left (the budget was spent)")
            return False
        start = time.monotonic()
        status = "ran"
        for c in commands:
            c = c(frames) if callable(c) else c
            cmd, tee = c if isinstance(c, tuple) else (c, None)
            status = self.run(cmd, tee)
            if status != "ran":
                break
        took = time.monotonic() - start
        entry.update(status=status, seconds=round(took, 1), frames=frames)
        if status == "ran" and estimate and self.budget and blocks is not None:
            self.budget.ratios.append(took / (estimate / self.budget.factor()))
        what = f" ({frames} frames" + (f"; estimated {estimate:.0f} s)" if estimate else ")") if frames else ""
        if status == "cut":
            log(self.out, f"{name}: cut at the budget after {took:.0f} s{what}; its finished runs are kept "
                          "(lodbench experiment FILE --resume finishes it)")
            self.stopped = True
        elif status == "failed":
            log(self.out, f"{name}: failed after {took:.0f} s{what}")
            raise SystemExit(1)
        else:
            log(self.out, f"{name}: {took:.0f} s{what}")
        return status == "ran"

    def write_budget(self):
        if not self.budget:
            return
        by = {s: [e["step"] for e in self.steps if e["status"] == s] for s in ("ran", "cut", "left")}
        spent = time.monotonic() - self.budget.start
        (self.out / "budget.json").write_text(json.dumps(
            {"budget_s": self.args.budget_s, "spent_s": round(spent, 1), "frames_most": self.args.frames,
             "min_frames": MIN_FRAMES, "rates": dict(zip(("triangles_per_s", "blended_fragments_per_s"),
                                                         getattr(self, "rates", (None, None)))),
             "factor": round(self.budget.factor(), 3), "steps": self.steps}, indent=2) + "\n")
        log(self.out, f"budget: {spent:.0f} s of {self.args.budget_s} s; ran: {', '.join(by['ran']) or 'none'}; "
                      f"cut: {', '.join(by['cut']) or 'none'}; left: {', '.join(by['left']) or 'none'}")


def experiment_commands(lb, out: Path, exp: str, extra=()):
    def run_it(frames):
        return [lb, "experiment", str(ROOT / "scenes" / "experiments" / f"{exp}.toml"), "--set", f"frames={frames}",
                "--set", f"warmup={WARMUP}", *extra, "--out", str(out / exp_dir(exp, extra))]
    return [run_it]


def exp_dir(exp, extra):
    return f"{exp}-no-warmup" if "clock-warmup=off" in extra else exp


def main(argv=None):
    p = argparse.ArgumentParser(prog="scripts/gpu-suite.sh", description=__doc__.split("\n\n")[0])
    p.add_argument("frames", nargs="?", default=os.environ.get("FRAMES", "150"))
    p.add_argument("experiments", nargs="*")
    p.add_argument("--budget-s", type=float, help="end within this many seconds, sizing each step's frames")
    p.add_argument("--out", type=Path, default=ROOT / "results" / "gpu", help="the folder of adapters' results")
    p.add_argument("--software", action="store_true", help="run on a software adapter (to test the budget logic)")
    args = p.parse_args(argv)
    try:
        return suite(args)
    except Refused as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


def suite(args):
    if not re.fullmatch(r"[0-9]+", str(args.frames)):
        raise Refused(f"FRAMES must be a whole number, not '{args.frames}'")
    args.frames = int(args.frames)
    for exp in args.experiments:
        if not (ROOT / "scenes" / "experiments" / f"{exp}.toml").is_file():
            raise Refused(f"no experiment '{exp}' (scenes/experiments/{exp}.toml); the suite's are: "
                          f"{' '.join(EXPERIMENTS)}")
    if args.budget_s is not None and args.budget_s <= 0:
        raise Refused(f"--budget-s must be a positive number of seconds, not {args.budget_s}")
    experiments = [e for e in EXPERIMENTS if not args.experiments or e in args.experiments]
    lb = os.environ.get("LODBENCH")
    if not lb:
        subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
        lb = str(ROOT / "target" / "release" / "lodbench")
    listing = subprocess.run([lb, "list"], capture_output=True, text=True).stdout.splitlines()
    best = next((re.sub(r"^ *[0-9]+  ", "", listing[i + 1]) for i, line in enumerate(listing)
                 if line.startswith("adapters") and i + 1 < len(listing)), "")
    if (not best or ", Cpu," in best) and not args.software:
        raise Refused(f"the best adapter is a software one ({best or 'none found'}): the GPU suite needs a GPU")
    name = re.sub(r"[^A-Za-z0-9._-]", "_", best.split("[")[0].strip())
    out = args.out / name
    out.mkdir(parents=True, exist_ok=True)
    s = Suite(args, lb, out)

    def stop(signum, _frame):
        s.stopped = True
        if s.child is not None:
            s.child.send_signal(signal.SIGTERM)
    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    log(out, f"adapter: {best}")
    if s.budget:
        log(out, f"budget: {args.budget_s:g} s, at most {args.frames} frames a step")
    try:
        run_steps(s, lb, out, experiments)
    finally:
        s.write_budget()
    print("\nThe claims that need a GPU (docs/claims.md); read them against the figures in", out)
    for line in (ROOT / "docs" / "claims.md").read_text().splitlines():
        if "**needs a GPU**" in line:
            print("|".join(line.split("|")[1:3]))
    return 0


def run_steps(s: Suite, lb, out: Path, experiments):
    py = sys.executable
    scripts = ROOT / "scripts"
    if not s.step("probe", [[lb, "probe", "--rounds", "20", "--out", str(out / "probe")]]):
        return
    s.rates = probe_rates(out / "probe") if s.budget else (None, None)
    scenes = Scenes(lb)

    def overhead(frames):
        return [lb, "overhead", "--scene", "bunny-grid", "--profile", "paper", "--count", "50,500,2000",
                "--frames", str(frames), "--rounds", "20", "--out", str(out / "overhead" / "bunny-grid")]

    def overhead_trees(frames):
        return [lb, "overhead", "--scene", "trees", "--profile", "paper", "--count", "400", "--frames", str(frames),
                "--rounds", "20", "--out", str(out / "overhead" / "trees")]
    s.step("overhead", [overhead, overhead_trees], overhead_blocks(scenes) if s.budget else None, s.args.frames)
    for exp in experiments:
        extra = ("--set", "dump-every=50") if exp == "trees-sorting" else ()
        after = []
        if exp == "aa-gpu":
            after.append(([py, str(scripts / "aa_check.py"), str(out / exp)], out / exp / "aa_check.md"))
        else:
            after.append([py, str(scripts / "plot.py"), str(out / exp)])
        if exp == "terrain-equal-error":
            after.append([py, str(scripts / "equal_error.py"), str(out / exp)])
        blocks = experiment_blocks(lb, scenes, exp) if s.budget else None
        s.step(exp, experiment_commands(lb, out, exp, extra) + after, blocks, s.args.frames)
        if exp == "terrain-equal-error":
            # The same without the clock's warm-up, then the blocks whose rate changed in each.
            extra = ("--set", "clock-warmup=off")
            clock = ([py, str(scripts / "clock_drops.py"), str(out / exp), str(out / f"{exp}-no-warmup")],
                     out / "clock_drops.md")
            s.step(f"{exp} without the clock warm-up", experiment_commands(lb, out, exp, extra) + [clock],
                   blocks, s.args.frames)


if __name__ == "__main__":
    sys.exit(main())
