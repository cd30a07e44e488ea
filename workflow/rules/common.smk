# Paths, wildcard constraints, input functions and narrow params of every rule. The workflow
# owns the file layout; the library receives the files (and only the settings) a job reads.
import os

import physgs.experiments.fit_curve as _fit_curve
import physgs.experiments.kselect as _kselect
import physgs.experiments.sweep as _sweep
import physgs.models.registry as _models
import physgs.provenance as _provenance
from physgs.experiments.recipe import canonical as _canonical
from physgs.experiments.recipe import job_spec as _job_spec
from physgs.recovery.run import null_settings as _null_settings
from physgs.report import build as _build

# Torch's OpenMP threads spin-wait by default, which starves the other job on a 2-core machine
# (measured: 20x slower projection); jobs inherit this environment.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

TREES = list(CFG["trees"])
CONFIGS = dict(CFG["models"]["configs"])  # name -> {conditions, K}
TRAIN_JOBS = _models.training_jobs(CONFIGS)
STAMP = _provenance.stamp(CFG)  # not a rerun trigger (see physgs.provenance.Stamp)

# ---- file layout ------------------------------------------------------------------------------
OBSERVED = "results/testbed/{tree}/observed.npz"
TRUTH = "results/testbed/{tree}/truth.npz"
STATS = "results/testbed/{tree}/stats.json"
CKPT = "results/models/{tree}/{model}_{config}.pt"
LOSS = "results/models/{tree}/{model}_{config}.loss.csv"
EVAL = "results/eval/{tree}/{model}_{config}.npz"
TRAJ = "results/eval/{tree}/{model}_{config}.traj.npz"
PANELS = "results/eval/{tree}/{model}_{config}.panels.npz"
RECOVERY = "results/recovery/{tree}/ours_{config}.json"
NULL = "results/recovery/{tree}/null_K{K}.json"
KSELECT = "results/kselect/{tree}.json"
SWEEP_POINT = "results/speed_accuracy/{point}.json"
FIT_POINT = "results/fit_curve/{tree}/{model}_it{iterations}.json"
TABLE = "results/tables/{name}.{ext}"
FIGURE = "results/figures/{name}.{ext}"
#: need kind (physgs.report.build.needs) -> path template
NEED_PATHS = {"eval": EVAL, "traj": TRAJ, "panels": PANELS, "loss": LOSS, "recovery": RECOVERY,
              "null": NULL, "kselect": KSELECT, "stats": STATS,
              "table": TABLE.replace("{ext}", "csv")}
SA_TREE = CFG["speed_accuracy"]["tree"]
SWEEP_POINTS = _sweep.sweep_points(CFG)
FC = CFG["speed_accuracy"]["fit_curve"]
#: the fit curve's profile-budget point is the pipeline's own job: these models' evaluations
FC_PROFILE_MODELS = ["static", *FC["models"], *_models.REFERENCE_NAMES]


wildcard_constraints:
    tree="|".join(TREES),
    model="|".join([*_models.MODEL_NAMES, *_models.REFERENCE_NAMES]),
    config="|".join([*CONFIGS, _models.AUTO_CONFIG]),
    K=r"\d+",
    point="|".join(SWEEP_POINTS),
    iterations=r"\d+",
    name="|".join([*_build.TABLES, *_build.FIGURES]),


# ---- input functions ----------------------------------------------------------------------
def train_input(wildcards):
    """The observed dataset of the tree; refuses (model, config) pairs that are never trained."""
    if wildcards.config not in _models.configs_for(wildcards.model, CONFIGS):
        raise ValueError(
            f"model '{wildcards.model}' is not trained in configuration '{wildcards.config}'; "
            f"valid: {_models.configs_for(wildcards.model, CONFIGS)} (joint configurations "
            "are ours only)")
    return OBSERVED.format(tree=wildcards.tree)


def need_paths(needs):
    """need key -> path for need tuples of physgs.report.build."""
    out = {}
    for need in needs:
        fields = dict(zip(_build.NEED_FIELDS[need[0]], need[1:]))
        out[_build.key(need)] = NEED_PATHS[need[0]].format(**fields)
    return out


def report_inputs(wildcards):
    """need key -> path of every file table or figure ``name`` reads."""
    return need_paths(_build.needs(wildcards.name, TREES, CONFIGS))


# ---- narrow params: each job sees only the settings it reads -------------------------------
def train_params(wildcards):
    return _job_spec(CFG, wildcards.model, wildcards.config)


def kselect_params(wildcards):
    return _canonical({"job": _job_spec(CFG, "ours", _models.BASE_CONFIG),
                       "kselect": CFG["models"]["kselect"]})


def null_params(wildcards):
    return _null_settings(CFG, int(wildcards.K))


def report_params(wildcards):
    return _canonical(_build.settings_for(wildcards.name, CFG))


def sweep_params(wildcards):
    return _sweep.point_settings(CFG, wildcards.point)


def fit_point_params(wildcards):
    return _fit_curve.point_job(CFG, wildcards.model, int(wildcards.iterations))


def fit_curve_inputs(wildcards):
    """The extra-budget points, and the pipeline's own evaluation and loss log of each model at
    the profile's budget."""
    tree, cfg = FC["tree"], _models.BASE_CONFIG
    return {
        "points": expand(FIT_POINT, tree=tree, model=FC["models"],
                         iterations=_fit_curve.extra_budgets(CFG)),
        **{f"eval_{m}": EVAL.format(tree=tree, model=m, config=cfg) for m in FC_PROFILE_MODELS},
        **{f"loss_{m}": LOSS.format(tree=tree, model=m, config=cfg) for m in FC_PROFILE_MODELS},
    }


def testbed_params(wildcards):
    t = wildcards.tree  # only this tree's vertex count: another tree's edit leaves it alone
    tb = {**CFG["testbed"], "vertices": {t: CFG["testbed"]["vertices"][t]}}
    return _canonical({"testbed": tb, "preset": CFG["presets"][t], "seed": int(CFG["seed"])})
