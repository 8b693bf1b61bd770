"""Every column the scripts read from lodbench's CSVs is one lodbench writes: a field of the Rust record the file is
serialised from (serde, one column per field), or a column an experiment or merged folder leads with.

scripts/lodbench_results.py declares, per CSV, the columns the scripts read (READS); this checks each against its
record, parsed from the Rust source (honouring serde's rename, rename_all, skip and flatten), and checks that every
column a script reads by a literal name (`row["x"]`, `row.get("x")`, a loop over literal names used as keys) is
declared there. Keys a script builds itself (its own dicts) are not columns and are left alone, as are the keys it
reads from JSON (NOT_COLUMNS below)."""
import ast
import re
import sys
from pathlib import Path

from conftest import ROOT

SCRIPTS = ROOT / "scripts"
sys.path.insert(0, str(SCRIPTS))
import lodbench_results as results  # noqa: E402

# The Rust record each CSV is written from (one row per value, serde's field order): (source file, struct).
RECORDS = {
    results.FRAMES_CSV: ("src/measure/records/rows.rs", "FrameRecord"),
    results.SUMMARY_CSV: ("src/measure/records/summaries.rs", "SummaryRecord"),
    results.TRANSITIONS_CSV: ("src/measure/records/transitions.rs", "TransitionRecord"),
    results.EVENTS_CSV: ("src/measure/records/events.rs", "EventRecord"),
    results.ROUNDS_CSV: ("src/measure/records/summaries.rs", "RoundRecord"),
    results.PAIRS_CSV: ("src/measure/records/summaries.rs", "PairRecord"),
    results.PERCEPTUAL_CSV: ("src/commands/perceptual.rs", "PerceptualRecord"),
    results.TUNE_CSV: ("src/measure/switch_tuning/outcome.rs", "Sample"),
    results.RULES_CSV: ("src/commands/tune.rs", "RuleRow"),
    results.PROBE_CSV: ("src/measure/probe_rounds.rs", "ProbeRecord"),
    results.OVERHEAD_CSV: ("src/measure/overhead_rounds.rs", "OverheadRecord"),
}

# Keys the scripts read that are not CSV columns: from lodbench's JSON (tune.json, run.json, `describe --json`, the
# engines' files of `lodbench tune`), from a glTF, from matplotlib, or of the script's own dicts keyed by a
# computed name.
TUNE_JSON_KEYS = {"settings", "budget", "metric", "views", "models", "pairs", "radius", "near", "width", "height"}
NOT_COLUMNS = {
    "chain_pop_vs_gltfpack.py": {
        "nodes", "children",  # the glTF
        "models", "triangles", "switch_distance",  # `lodbench describe --json`
        # its rows' columns, named by f"{name}_{column}"
        "lodbench_triangles", "lodbench_lodpop_max", "lodbench_lodpop_coverage", "lodbench_lodpop_shading",
        "gltfpack_triangles", "gltfpack_lodpop_max", "gltfpack_lodpop_coverage", "gltfpack_lodpop_shading",
    },
    "engine_check.py": TUNE_JSON_KEYS | {
        "eye",  # `lodbench describe --cameras-json`
        "scenes", "schedule", "fade", "fade_frames",  # run.json's config and the score folder's job
        "notes", "objects", "position",  # score.json's notes, which three_lod.py writes
        "object", "lod",  # lods.csv, the score folder's (written by three_lod.py, read by `lodbench score`)
        "flip_mean_flat", "flip_covered",  # three_fidelity.py's rows
    },
    "equal_error.py": {"triangles", "cost"},  # its points' values, named by COLUMNS
    "frontier.py": {"axes.prop_cycle", "color"},  # matplotlib's rcParams
    "gpu_suite.py": {
        "triangles", "triangles-instanced", "fill-blended",  # probe.csv's rows, keyed by its `probe` column
        "models", "instance_counts", "width", "height",  # `lodbench describe --json` (a model's lods' triangles)
        "run", "sweep", "profile", "quality", "variable", "variables", "values",  # an experiment file's TOML
        "status", "ran", "cut", "left",  # its own budget.json entries
        "FRAMES", "LODBENCH",  # the environment
    },
    "plot.py": TUNE_JSON_KEYS | {
        "fov_y_deg", "band", "bands", "switch_distance", "triangles_from", "triangles_to", "value_at_switch",
        "checked_worst", "error_px_at_switch",  # tune.json
        "schema", "blocks", "name", "sentences", "columns", "rows", "budget", "lodpop", "source",  # answer.json
        "LODBENCH", "LODBENCH_BIN", "CARGO_TARGET_DIR",  # the environment, where the binary is
        "lod", "screenRelativeTransitionHeight", "visibility_range_end", "end_margin",  # tune's engines/*.json
        "color",  # matplotlib's rcParams
    },
    "tune_rules.py": TUNE_JSON_KEYS | {
        "eye",  # `lodbench describe --camera-json`
        "diagonal", "discrete",  # its dicts keyed by path and by method
    },
}


# ---- The Rust records ----

def without_comments(source: str) -> str:
    return re.sub(r"//[^\n]*", "", source)


def serde_attrs(attrs: str) -> str:
    """The inside of every #[serde(...)] of `attrs`, joined by commas."""
    return ",".join(re.findall(r"#\[\s*serde\s*\((.*?)\)\s*\]", attrs, re.S))


def split_top(text: str, sep=","):
    """`text` split at `sep` outside brackets (generics, tuples, arrays, blocks)."""
    parts, depth, start = [], 0, 0
    for i, c in enumerate(text):
        if c in "<([{":
            depth += 1
        elif c in ">)]}":
            depth -= 1
        elif c == sep and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p for p in parts if p.strip()]


def rename_all(name: str, rule: str) -> str:
    words = name.split("_")
    return {
        "lowercase": name.lower(), "UPPERCASE": name.upper(), "snake_case": name,
        "SCREAMING_SNAKE_CASE": name.upper(), "kebab-case": "-".join(words),
        "SCREAMING-KEBAB-CASE": "-".join(words).upper(),
        "camelCase": words[0] + "".join(w.capitalize() for w in words[1:]),
        "PascalCase": "".join(w.capitalize() for w in words),
    }[rule]


def find_struct(name: str, source: str):
    """(the attributes before `struct name`, its body between the braces), or None."""
    source = without_comments(source)
    m = re.search(r"((?:#\[[^\]]*\]\s*)*)(?:pub(?:\([^)]*\))?\s+)?struct\s+" + re.escape(name) + r"\b[^{;(]*\{", source)
    if m is None:
        return None
    depth, i = 1, m.end()
    while depth:
        depth += {"{": 1, "}": -1}.get(source[i], 0)
        i += 1
    return m.group(1), source[m.end():i - 1]


def rust_fields(path: str, name: str, root: Path = ROOT):
    """The columns of struct `name` of `path` (relative to `root`, the repository) as serde writes them, in order:
    each field under its serialised name, a flattened field's own fields in its place, skipped fields left out. A
    flattened struct is looked up in the same file, then anywhere under src/."""
    found = find_struct(name, (root / path).read_text())
    if found is None:
        for other in sorted((root / "src").rglob("*.rs")):
            found = find_struct(name, other.read_text())
            if found is not None:
                path = str(other.relative_to(root))
                break
    assert found is not None, f"no struct {name} in {path} or under src/"
    attrs, body = found
    rule = re.search(r'rename_all\s*=\s*"([^"]+)"', serde_attrs(attrs))
    out = []
    for field in split_top(body):
        m = re.fullmatch(r"\s*((?:#\[.*?\]\s*)*)(?:pub(?:\([^)]*\))?\s+)?(?:r#)?(\w+)\s*:(.*)", field, re.S)
        assert m, f"{path}: struct {name}: cannot read the field {field.strip()!r}"
        serde = serde_attrs(m.group(1))
        if re.search(r"\bskip(_serializing)?\b", serde):
            continue
        if re.search(r"\bflatten\b", serde):
            inner = re.sub(r"^(?:Option<)?(?:[\w:]*::)?(\w+).*$", r"\1", m.group(3).strip(), flags=re.S)
            out += rust_fields(path, inner, root)
            continue
        renamed = re.search(r'rename\s*(?:=\s*|\(\s*serialize\s*=\s*)"([^"]+)"', serde)
        out.append(renamed.group(1) if renamed else rename_all(m.group(2), rule.group(1)) if rule else m.group(2))
    return out


def header(csv_name: str):
    return rust_fields(*RECORDS[csv_name])


def test_the_parser_honours_serde(tmp_path):
    source = '''
        /// A record.
        #[derive(Serialize)]
        #[serde(rename_all = "kebab-case")]
        pub struct Outer<'a> {
            /// A doc comment, with a colon: and a comma, in it.
            pub scene_name: &'a str,
            #[serde(rename = "n")]
            pub count: u32,
            #[serde(skip)]
            pub hidden: Vec<(u32, f64)>,
            #[serde(skip_serializing_if = "Option::is_none")]
            pub kept: Option<std::collections::HashMap<String, u32>>,
            #[serde(flatten)]
            pub inner: Inner,
            last: [f32; 3],
        }

        #[derive(Serialize)]
        struct Inner {
            pub a_b: f64, // a trailing comment
            #[serde(skip_serializing)]
            pub c: f64,
        }
    '''
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "x.rs").write_text(source)
    assert rust_fields("src/x.rs", "Outer", tmp_path) == ["scene-name", "n", "kept", "a_b", "last"]


def test_every_record_parses():
    for csv_name, (path, name) in RECORDS.items():
        fields = header(csv_name)
        assert fields and len(set(fields)) == len(fields), f"{csv_name}: {path}'s {name} gives {fields}"


def test_the_parsed_records_are_the_headers_lodbench_writes(dump):
    """The parse against a run's own CSVs: the same columns in the same order."""
    for csv_name in (results.FRAMES_CSV, results.SUMMARY_CSV, results.TRANSITIONS_CSV, results.EVENTS_CSV,
                     results.ROUNDS_CSV, results.PAIRS_CSV):
        written = (dump / csv_name).read_text().splitlines()[0].split(",")
        assert header(csv_name) == written, csv_name


def test_every_column_the_scripts_read_is_in_its_record():
    assert set(results.READS) <= set(RECORDS), "a CSV of READS with no record in RECORDS"
    missing = {f: [c for c in cols if c not in header(f)] for f, cols in results.READS.items()}
    missing = {f: cols for f, cols in missing.items() if cols}
    assert not missing, (f"lodbench_results.READS names columns that no record writes: {missing} (the records: "
                         + ", ".join(f"{f}: {RECORDS[f][1]} in {RECORDS[f][0]}" for f in missing) + ")")


def test_the_lead_columns_are_lodbench_s():
    """`adapter` is the column `lodbench merge` adds; a swept variable is `viewport` or a `lodbench run` flag."""
    merge = (ROOT / "src/commands/merge.rs").read_text()
    experiment = (ROOT / "src/cli/experiment_file.rs").read_text()
    cli = (ROOT / "src/cli/mod.rs").read_text()
    for c in results.LEAD_COLUMNS:
        if c == "adapter":
            assert '.push("adapter")' in merge
        elif c == "viewport":
            assert 'const VIEWPORT: &str = "viewport";' in experiment
        else:
            assert re.search(rf"\bpub {c.replace('-', '_')}:", cli), f"{c}: no `lodbench run --{c}` in src/cli/mod.rs"


# ---- What the scripts read ----

def is_name(node) -> bool:
    return isinstance(node, ast.Constant) and isinstance(node.value, str)


def used_as_key(scope, name: str) -> bool:
    """Whether variable `name` indexes something in `scope` (`x[name]`, `x.get(name)`)."""
    for n in ast.walk(scope):
        if isinstance(n, ast.Subscript) and isinstance(n.slice, ast.Name) and n.slice.id == name:
            return True
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and n.func.attr == "get" and n.args \
                and isinstance(n.args[0], ast.Name) and n.args[0].id == name:
            return True
    return False


def reads(tree):
    """(key, line) of every key the module reads by a literal name: `x["k"]`, `x.get("k")`, and the names of a
    literal tuple or list a loop or comprehension goes over when its variable indexes something in it."""
    for n in ast.walk(tree):
        if isinstance(n, ast.Subscript) and isinstance(n.ctx, ast.Load) and is_name(n.slice):
            yield n.slice.value, n.lineno
        elif isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and n.func.attr == "get" and n.args \
                and is_name(n.args[0]):
            yield n.args[0].value, n.lineno
        if isinstance(n, ast.For):
            loops = [(n.target, n.iter)]
        elif isinstance(n, (ast.ListComp, ast.SetComp, ast.GeneratorExp, ast.DictComp)):
            loops = [(g.target, g.iter) for g in n.generators]
        else:
            loops = []
        for target, over in loops:
            if isinstance(target, ast.Name) and isinstance(over, (ast.Tuple, ast.List)) and over.elts \
                    and all(is_name(e) for e in over.elts) and used_as_key(n, target.id):
                yield from ((e.value, e.lineno) for e in over.elts)


def built(tree):
    """The keys the module builds itself: of its dict displays, and those it assigns (`x["k"] = ...`)."""
    out = set()
    for n in ast.walk(tree):
        if isinstance(n, ast.Dict):
            out |= {k.value for k in n.keys if is_name(k)}
        elif isinstance(n, ast.Subscript) and isinstance(n.ctx, ast.Store) and is_name(n.slice):
            out.add(n.slice.value)
    return out


def csv_readers():
    """The scripts that read lodbench's CSVs: those taking a CSV's name or a CSV reader from lodbench_results."""
    for path in sorted(SCRIPTS.glob("*.py")):
        if path.name == "lodbench_results.py":
            continue
        tree = ast.parse(path.read_text(), str(path))
        taken = {a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module == "lodbench_results"
                 for a in n.names}
        if any(t.endswith("_CSV") or t in ("read_csv", "frames_by_key") for t in taken):
            yield path, tree


def test_the_scripts_read_only_declared_columns():
    declared = {c for cols in results.READS.values() for c in cols} | set(results.LEAD_COLUMNS)
    scanned, problems = [], []
    for path, tree in csv_readers():
        scanned.append(path.name)
        own = built(tree) | NOT_COLUMNS.get(path.name, set())
        for key, line in sorted(set(reads(tree))):
            if key not in declared and key not in own:
                problems.append(f"scripts/{path.name}:{line} reads {key!r}")
    # The scan sees the scripts that read lodbench's CSVs (or it would pass by seeing nothing).
    assert {"aa_check.py", "frontier.py", "plot.py", "tune_rules.py"} <= set(scanned), scanned
    assert not problems, (
        "columns read by name that lodbench_results.READS does not declare:\n  " + "\n  ".join(problems)
        + "\nA column of one of lodbench's CSVs goes into READS under its file (and must be in its Rust record); a "
          "key read from JSON or another source goes into NOT_COLUMNS of scripts/tests/test_columns.py.")


def test_the_scripts_column_tables_are_declared():
    """The scripts' tables of summary.csv columns, which the scan above does not see as reads."""
    import equal_error
    import plot

    tables = {
        "plot.SUMMARY_GROUPS": [c for _, cols in plot.SUMMARY_GROUPS for c in cols],
        "plot.COUNT_COLUMNS": sorted(plot.COUNT_COLUMNS),
        "equal_error.COLUMNS": [c for _, c in equal_error.COLUMNS if c is not None],
    }
    summary = set(results.READS[results.SUMMARY_CSV])
    undeclared = {t: [c for c in cols if c not in summary] for t, cols in tables.items()}
    assert not any(undeclared.values()), f"summary.csv columns missing from lodbench_results.READS: {undeclared}"
