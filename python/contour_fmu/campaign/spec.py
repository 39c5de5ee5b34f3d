"""Campaign: a campaign file (TOML) read, checked against the FMUs' model descriptions and
expanded into runs. Everything a user can get wrong is refused here, before any run starts,
with a CampaignError that names the file and the entry.

The file (every key but `loop` optional; docs/campaigns.md has the whole reference):

    name = "two-axis robustness"
    loop = "two_axis"                  # or "five_axis" (contour_fmu.loops.wiring)
    step = 0.001                       # communication step (s)
    stop = "end_of_path"               # or a stop time in seconds
    settle = 0.05                      # seconds run after the end of the path
    metrics = ["contour_error.max", "contour_error.mean"]
    engine = "native"                  # contour-cosim (default), or "fmpy"
    timeout = 60.0                     # native: an FMU call longer than this ends its run
    batch_size = "auto"                # runs per Dask task (one set of instances); auto:
                                       #   about a second of work each

    [fmus]                             # default: the loop's FMUs in <repo>/target/fmu
    directory = "../target/fmu"        # relative to this file; or one file per unit:
    controller = "ContourCCC2D.fmu"    # interpolator / controller / plant

    [fixed]                            # start values of every run
    "controller.ccc.limit" = 5.0

    [[paths]]                          # interpolator path and feed, one group of runs each
    path = "circle"
    feed = 31.41592653589793

    [[variants]]                       # named sets of start values
    name = "PSO-tuned"
    tuned = "tuned.json"               # a ccc-tune result: controller fuzzy.* factors
    parameters = { "controller.ccc.enable" = true }

    [sweep]
    method = "latin_hypercube"         # or "grid" (every combination)
    samples = 32                       # latin_hypercube only
    seed = 1
    [sweep.parameters]
    "plant.x.J" = { factor_range = [0.8, 1.2] }   # latin_hypercube: times the FMU's start
    "plant.x.B" = { range = [0.001, 0.002] }      #   value, or absolute
    # grid: { values = [...] } or { factors = [0.8, 1.0, 1.2] }

Runs are numbered variant by variant, path by path, sweep point by sweep point; a run's
number and its start values depend on the file and the FMUs only, which is what lets
--resume and replay find it again.
"""

import functools
import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .. import repo
from ..extras import needs
from ..loops.wiring import LOOPS
from ..tuned import start_values as tuned_start_values
from .metrics import METRICS, check_metrics

METHODS = ("grid", "latin_hypercube")
STOP_AT_END = "end_of_path"
# A run that has not reached the end of its path after this long is an error, not a hang.
DEFAULT_MAX_STOP = 600.0
# More runs than this is a typo in a grid, not a campaign (and would fill memory first).
MAX_RUNS = 1_000_000
TOP_KEYS = {"name", "loop", "step", "stop", "settle", "max_stop", "metrics", "batch_size",
            "engine", "timeout", "fmus", "fixed", "paths", "variants", "sweep"}
# Who steps the FMUs: contour-cosim (contour_fmu.engines.native), or fmpy in the worker's Python.
ENGINES = ("native", "fmpy")
AUTO = "auto"


class CampaignError(ValueError):
    """A campaign file that cannot run; the message names the file and the entry."""


@dataclass(frozen=True)
class Variable:
    """What a campaign needs of one FMU variable."""
    type: str  # Real, Integer, Boolean, String, Enumeration
    causality: str
    start: object  # the model description's start value, converted, or None
    min: float | None = None  # the model description's bounds (numbers only)
    max: float | None = None
    items: tuple = ()  # an Enumeration's values


@dataclass(frozen=True)
class Unit:
    """One FMU of the loop: its file, its SHA-256, its variables by name."""
    name: str
    path: Path
    sha256: str
    variables: dict


@dataclass(frozen=True)
class Run:
    id: int
    variant: str
    path: str  # the path's label
    swept: dict  # "unit.variable" -> value, this run's sweep point
    start_values: dict  # unit -> {variable: value}: fixed, path, variant, swept (later wins)


@dataclass(frozen=True)
class Campaign:
    name: str
    source: Path
    loop: str
    units: dict  # unit name -> Unit
    step: float
    stop: float | None  # None: at the end of the path (+ settle)
    settle: float
    max_stop: float
    metrics: tuple
    batch_size: int | None  # None: sized by work (execute.BatchSizer)
    swept: tuple  # "unit.variable" names, in file order
    runs: tuple = field(repr=False)
    fmu_dir: Path | None = None  # --fmu-dir, when given (replay commands repeat it)
    engine: str = "native"  # not in the digest: both engines give the same rows
    timeout: float = 60.0  # seconds an FMU call may take (native engine)

    @functools.cached_property
    def digest(self):
        """SHA-256 of everything that decides the results: the FMUs, the loop, the timing,
        the metrics and every run's start values. --resume refuses another digest."""
        from .. import __version__

        document = {
            "package": __version__, "swept": list(self.swept), "loop": self.loop, "step": self.step, "stop": self.stop, "settle": self.settle,
            "max_stop": self.max_stop, "metrics": list(self.metrics),
            "fmus": {name: unit.sha256 for name, unit in self.units.items()},
            "runs": [[r.id, r.variant, r.path, r.start_values] for r in self.runs],
        }
        return hashlib.sha256(json.dumps(document, sort_keys=True).encode()).hexdigest()

    def run(self, run_id):
        if not 0 <= run_id < len(self.runs):
            raise CampaignError(f"{self.source}: no run {run_id} (runs 0 to {len(self.runs) - 1})")
        return self.runs[run_id]


def load(filename, fmu_dir=None):
    """The campaign in `filename`, checked and expanded; `fmu_dir` overrides the file's
    FMU folder. Raises CampaignError."""
    source = Path(filename)
    try:
        document = tomllib.loads(source.read_text())
    except OSError as e:
        raise CampaignError(f"cannot read the campaign file {source}: {e.strerror or e}") from None
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise CampaignError(f"{source}: not a TOML file: {e}") from None
    return _Reader(source, document, fmu_dir).campaign()


class _Reader:
    def __init__(self, source, document, fmu_dir):
        self.source, self.doc, self.fmu_dir = source, document, fmu_dir

    def fail(self, message):
        raise CampaignError(f"{self.source}: {message}")

    def only(self, keys, allowed, where):
        """Refuses keys outside `allowed` (a typo must not be silently ignored)."""
        unknown = sorted(set(keys) - set(allowed))
        if unknown:
            self.fail(f"{where}: unknown key {', '.join(unknown)} (expected some of "
                      f"{', '.join(sorted(allowed))})")

    def campaign(self):
        self.only(self.doc, TOP_KEYS, "the top level")
        loop = self.doc.get("loop")
        if loop not in LOOPS:
            self.fail(f"loop = {loop!r}: expected one of {', '.join(LOOPS)}")
        self.loop = loop
        self.units = self.read_units()
        step = self.positive("step", 1e-3)
        stop = self.doc.get("stop", STOP_AT_END)
        if stop != STOP_AT_END:
            stop = self.positive("stop", None)
            if stop < step:
                self.fail(f"stop = {stop!r} is shorter than one step ({step!r} s)")
        settle = self.number("settle", 0.0, minimum=0.0)
        max_stop = self.positive("max_stop", DEFAULT_MAX_STOP)
        if isinstance(stop, float) and stop > max_stop:
            self.fail(f"stop = {stop!r} is beyond max_stop = {max_stop!r}")
        if isinstance(stop, float) and "settle" in self.doc:
            self.fail("settle applies to stop = \"end_of_path\"; with a stop time, lengthen the stop")
        if max_stop / step > 1e8:
            self.fail(f"max_stop / step = {max_stop / step:.3g} steps: more than 1e8 per run")
        batch_size = self.doc.get("batch_size", AUTO)
        if batch_size == AUTO:
            batch_size = None
        elif not isinstance(batch_size, int) or isinstance(batch_size, bool) or batch_size < 1:
            self.fail(f"batch_size = {batch_size!r}: expected a whole number >= 1 or \"auto\"")
        engine = self.doc.get("engine", "native")
        if engine not in ENGINES:
            self.fail(f"engine = {engine!r}: expected one of {', '.join(map(repr, ENGINES))}")
        timeout = self.positive("timeout", 60.0)
        metrics = self.doc.get("metrics", list(METRICS[loop].names[:2]))
        try:
            check_metrics(loop, metrics)
        except ValueError as e:
            self.fail(str(e))

        fixed = self.assignments(self.table("fixed"), "[fixed]")
        paths = self.read_paths()
        variants = self.read_variants()
        swept, points = self.read_sweep()
        if len(variants) * len(paths) * len(points) > MAX_RUNS:
            self.fail(f"{len(variants)} variants × {len(paths)} paths × {len(points)} sweep points "
                      f"is more than {MAX_RUNS} runs")
        runs = []
        for variant, variant_values in variants:
            for label, path_values in paths:
                for point in points:
                    values = {}
                    for part in (fixed, path_values, variant_values, point):
                        for (unit, name), value in part.items():
                            values.setdefault(unit, {})[name] = value
                    runs.append(Run(len(runs), variant, label,
                                    {f"{u}.{n}": v for (u, n), v in point.items()}, values))
        for run in runs:
            interpolator = run.start_values.get("interpolator", {})
            feed = interpolator.get("feed", self.units["interpolator"].variables["feed"].start)
            if feed is not None and feed <= 0:
                self.fail(f"run {run.id} ({run.variant}, {run.path}): interpolator.feed = {feed!r}: "
                          "expected a feed > 0")
            try:
                check_metrics(loop, metrics, interpolator, self.units["interpolator"].variables)
            except ValueError as e:
                self.fail(f"path {run.path!r}: {e}")
        return Campaign(
            name=str(self.doc.get("name", self.source.stem)), source=self.source.resolve(),
            fmu_dir=None if self.fmu_dir is None else Path(self.fmu_dir).resolve(),
            loop=loop, units=self.units, step=step, stop=None if stop == STOP_AT_END else stop,
            settle=settle, max_stop=max_stop, metrics=tuple(metrics), batch_size=batch_size,
            swept=tuple(swept), runs=tuple(runs), engine=engine, timeout=timeout)

    # --- scalars -----------------------------------------------------------------------

    def number(self, key, default, minimum=None):
        value = self.doc.get(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(f"{key} = {value!r}: expected a finite number")
        if minimum is not None and value < minimum:
            self.fail(f"{key} = {value!r}: expected at least {minimum!r}")
        return float(value)

    def positive(self, key, default):
        value = self.number(key, default)
        if value <= 0:
            self.fail(f"{key} = {value!r}: expected a number > 0")
        return value

    def table(self, key, within=None, name=None):
        value = (self.doc if within is None else within).get(key, {})
        if not isinstance(value, dict):
            self.fail(f"{name or key}: expected a table")
        return value

    # --- FMUs and their variables ------------------------------------------------------

    def read_units(self):
        from fmpy import read_model_description

        fmus = self.table("fmus", name="[fmus]")
        loop = LOOPS[self.loop]
        self.only(fmus, {"directory", *loop.units}, "[fmus]")
        for key, value in fmus.items():
            if not isinstance(value, str):
                self.fail(f"[fmus] {key} = {value!r}: expected a file or folder name (a string)")
        if self.fmu_dir is not None:
            directory = Path(self.fmu_dir)
        elif "directory" in fmus:
            directory = self.source.parent / fmus["directory"]
        else:
            try:
                directory = repo.fmu_dir()
            except repo.RepoNotFound as e:
                self.fail(f"no [fmus] directory and {e}")
        units = {}
        for unit, default in loop.units.items():
            path = Path(directory) / default
            if unit in fmus and self.fmu_dir is None:  # --fmu-dir replaces every entry
                path = self.source.parent / fmus[unit]
            if not path.is_file():
                self.fail(f"no FMU {path} for the {unit} (build the FMUs with `make fmus`, "
                          f"or name them in [fmus])")
            try:
                md = read_model_description(str(path))
            except Exception as e:  # noqa: BLE001  fmpy raises anything on a bad archive
                self.fail(f"{path} is not a readable FMU: {e}")
            expected = Path(default).stem
            if md.coSimulation is None:
                self.fail(f"{path}: exported for Model Exchange only (no <CoSimulation>): a "
                          f"co-simulation master cannot step it (it needs an ODE solver the "
                          f"FMU does not carry); export it for Co-Simulation")
            if md.modelName != expected:
                self.fail(f"{path} is {md.modelName!r}, not the {unit} of the {self.loop} "
                          f"loop ({expected}, FMI 2.0 Co-Simulation)")
            in_metres = [v.name for v in md.modelVariables if v.unit == "m"]
            if in_metres:
                self.fail(f"{path} speaks SI ({unit}.{in_metres[0]} is in m): a campaign's "
                          "metrics are in mm and rad; run it on the mm build's FMUs (target/fmu, "
                          "not target/fmu-si)")
            variables = {v.name: Variable(v.type, v.causality, _start(v), _bound(v.min), _bound(v.max),
                                          _items(v)) for v in md.modelVariables}
            units[unit] = Unit(unit, path.resolve(), _sha256(path), variables)
        return units

    def variable(self, target, where, path_allowed=False):
        """(unit, variable name) of a "unit.variable" that a campaign may set."""
        unit, _, name = str(target).partition(".")
        if unit not in self.units or not name:
            self.fail(f"{where}: {target!r} is not unit.variable with unit one of "
                      f"{', '.join(self.units)}")
        variable = self.units[unit].variables.get(name)
        if variable is None:
            self.fail(f"{where}: {self.units[unit].path.name} has no variable {name!r}")
        if variable.causality != "parameter":
            self.fail(f"{where}: {unit}.{name} is an {variable.causality}, not a parameter")
        if (unit, name) == ("interpolator", "path") and not path_allowed:
            self.fail(f"{where}: the path is chosen in [[paths]] (each path is a group of its own "
                      "in the summary)")
        if (unit, name) in {(dst, inp) for _, _, dst, inp in LOOPS[self.loop].path_start}:
            self.fail(f"{where}: {unit}.{name} is set by the loop (the plant starts where the path does)")
        return unit, name, variable

    def value(self, variable, value, where):
        """`value` checked against the variable's type (TOML types: numbers for Real and
        Integer, true/false for Boolean, strings for String) and its bounds in the model
        description."""
        kind = variable.type
        if kind == "Real" and isinstance(value, (int, float)) and not isinstance(value, bool):
            if not math.isfinite(value):
                self.fail(f"{where} = {value!r}: not a finite number")
            return self.bounded(variable, float(value), where)
        if kind in ("Integer", "Enumeration") and isinstance(value, int) and not isinstance(value, bool):
            if not -2**31 <= value < 2**31:
                self.fail(f"{where} = {value!r}: outside the 32-bit range of an FMI Integer")
            if variable.items and value not in dict(variable.items):
                self.fail(f"{where} = {value!r}: not one of the enumeration's values "
                          + ", ".join(f"{v} ({n})" for v, n in variable.items))
            return self.bounded(variable, value, where)
        if kind == "Boolean" and isinstance(value, bool):
            return value
        if kind == "String" and isinstance(value, str):
            return value
        self.fail(f"{where} = {value!r}: expected a {kind} value")

    def bounded(self, variable, value, where):
        if variable.min is not None and value < variable.min:
            self.fail(f"{where} = {value!r}: below the variable's minimum {variable.min!r}")
        if variable.max is not None and value > variable.max:
            self.fail(f"{where} = {value!r}: above the variable's maximum {variable.max!r}")
        return value

    def assignments(self, table, where):
        result = {}
        for target, value in table.items():
            unit, name, variable = self.variable(target, where)
            result[(unit, name)] = self.value(variable, value, f"{where} {target}")
        return result

    # --- paths, variants, sweep --------------------------------------------------------

    def entries(self, key):
        value = self.doc.get(key, [])
        if not isinstance(value, list) or not all(isinstance(e, dict) for e in value):
            self.fail(f"{key}: expected an array of tables ([[{key}]])")
        return value

    def read_paths(self):
        entries = self.entries("paths")
        if not entries:
            default = self.units["interpolator"].variables["path"].start
            return [(default, {})]
        paths, labels = [], set()
        for i, entry in enumerate(entries):
            where = f"[[paths]] #{i + 1}"
            self.only(entry, {"path", "feed", "label"}, where)
            if "path" not in entry:
                self.fail(f"{where}: no path")
            values = {("interpolator", "path"): self.value(
                self.units["interpolator"].variables["path"], entry["path"], f"{where} path")}
            if "feed" in entry:
                feed = self.value(self.units["interpolator"].variables["feed"], entry["feed"], f"{where} feed")
                if feed <= 0:
                    self.fail(f"{where} feed = {feed!r}: expected a feed > 0")
                values[("interpolator", "feed")] = feed
            label = str(entry.get("label", entry["path"]))
            if label in labels:
                self.fail(f"{where}: a second path labelled {label!r} (give each a label)")
            labels.add(label)
            paths.append((label, values))
        return paths

    def read_variants(self):
        entries = self.entries("variants")
        if not entries:
            return [("default", {})]
        variants, names = [], set()
        for i, entry in enumerate(entries):
            where = f"[[variants]] #{i + 1}"
            self.only(entry, {"name", "tuned", "parameters"}, where)
            name = entry.get("name")
            if not isinstance(name, str) or not name or name in names:
                self.fail(f"{where}: expected a name of its own, got {name!r}")
            names.add(name)
            values = {}
            if "tuned" in entry:
                if self.loop != "two_axis":
                    self.fail(f"{where}: tuned (a ccc-tune result) applies to the two-axis loop only")
                try:
                    tuned = tuned_start_values(self.source.parent / entry["tuned"])
                except (OSError, ValueError, KeyError, TypeError) as e:
                    self.fail(f"{where}: tuned = {entry['tuned']!r}: {e}")
                values.update(self.assignments({f"controller.{k}": v for k, v in tuned.items()}, where))
            parameters = self.table("parameters", entry, f"{where} parameters")
            values.update(self.assignments(parameters, f"{where} parameters"))
            variants.append((name, values))
        return variants

    def read_sweep(self):
        """(swept names, list of points {(unit, name): value}); no sweep is one point."""
        sweep = self.table("sweep", name="[sweep]")
        if not sweep:
            return [], [{}]
        self.only(sweep, {"method", "samples", "seed", "parameters"}, "[sweep]")
        method = sweep.get("method", "grid")
        if method not in METHODS:
            self.fail(f"[sweep] method = {method!r}: expected one of {', '.join(METHODS)}")
        parameters = self.table("parameters", sweep, "[sweep.parameters]")
        if not parameters:
            self.fail("[sweep.parameters]: no parameter to sweep")
        if method == "grid":
            return self.grid(parameters)
        return self.latin_hypercube(sweep, parameters)

    def relative_base(self, unit, name, variable, where):
        if variable.type != "Real" or variable.start is None or variable.start == 0:
            self.fail(f"{where}: factors need a Real parameter with a non-zero start value; "
                      f"{unit}.{name} has {variable.type} start {variable.start!r}")
        return variable.start

    def grid(self, parameters):
        import itertools

        names, axes = [], []
        for target, entry in parameters.items():
            where = f"[sweep.parameters] {target}"
            unit, name, variable = self.variable(target, where)
            if not isinstance(entry, dict) or len(set(entry) & {"values", "factors"}) != 1 or len(entry) != 1:
                self.fail(f"{where}: a grid takes {{ values = [...] }} or {{ factors = [...] }}")
            (kind, levels), = entry.items()
            if not isinstance(levels, list):
                self.fail(f"{where}: {kind} must be an array")
            if not levels:
                self.fail(f"{where}: empty grid ({kind} = []): the campaign would have no run")
            if kind == "factors":
                base = self.relative_base(unit, name, variable, where)
                levels = [self.value(variable, base * self.factor(f, where), f"{where} factor {f!r}")
                          for f in levels]
            else:
                levels = [self.value(variable, v, where) for v in levels]
            names.append((unit, name))
            axes.append(levels)
        points = [dict(zip(names, combination)) for combination in itertools.product(*axes)]
        return [f"{u}.{n}" for u, n in names], points

    def factor(self, f, where):
        if isinstance(f, bool) or not isinstance(f, (int, float)) or not math.isfinite(f):
            self.fail(f"{where}: factor {f!r} is not a finite number")
        return float(f)

    def latin_hypercube(self, sweep, parameters):
        with needs("campaign"):
            from scipy.stats import qmc

        samples, seed = sweep.get("samples"), sweep.get("seed", 0)
        if not isinstance(samples, int) or isinstance(samples, bool) or samples < 1:
            self.fail(f"[sweep] samples = {samples!r}: a latin_hypercube needs samples >= 1")
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
            self.fail(f"[sweep] seed = {seed!r}: expected a whole number >= 0")
        names, bounds = [], []
        for target, entry in parameters.items():
            where = f"[sweep.parameters] {target}"
            unit, name, variable = self.variable(target, where)
            if not isinstance(entry, dict) or len(entry) != 1 or not set(entry) <= {"range", "factor_range"}:
                self.fail(f"{where}: a latin_hypercube takes {{ range = [lo, hi] }} "
                          "or {{ factor_range = [lo, hi] }}")
            if variable.type != "Real":
                self.fail(f"{where}: a latin_hypercube samples Real parameters; {unit}.{name} is {variable.type}")
            (kind, pair), = entry.items()
            if not isinstance(pair, list) or len(pair) != 2:
                self.fail(f"{where}: {kind} must be [lo, hi]")
            lo, hi = (self.factor(v, where) for v in pair)
            if kind == "factor_range":
                base = self.relative_base(unit, name, variable, where)
                lo, hi = sorted((lo * base, hi * base))
            if not lo < hi:
                self.fail(f"{where}: empty range [{lo!r}, {hi!r}]")
            self.bounded(variable, lo, f"{where} {kind}")
            self.bounded(variable, hi, f"{where} {kind}")
            names.append((unit, name))
            bounds.append((lo, hi))
        unit_cube = qmc.LatinHypercube(d=len(names), rng=seed).random(samples)
        lows, highs = zip(*bounds)
        scaled = qmc.scale(unit_cube, lows, highs)
        points = [{key: float(v) for key, v in zip(names, row)} for row in scaled]
        return [f"{u}.{n}" for u, n in names], points


def _start(variable):
    """A model variable's start value as a Python value (fmpy gives strings)."""
    start = variable.start
    if start is None:
        return None
    if variable.type == "Real":
        return float(start)
    if variable.type in ("Integer", "Enumeration"):
        return int(start)
    if variable.type == "Boolean":
        return start in (True, "true", "1", 1)
    return start


def _bound(text):
    return None if text is None else float(text)


def _items(variable):
    """((value, name), ...) of an Enumeration variable's type."""
    if variable.type != "Enumeration" or variable.declaredType is None:
        return ()
    return tuple((int(item.value), item.name) for item in variable.declaredType.items)


def _sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()
