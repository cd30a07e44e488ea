# The speed-accuracy trade (the protocol, section 5): one knob at a time away from the profile's settings,
# ours on one tree, trained by the tables' recipe; `snakemake --cores 2 speed_accuracy`.


rule speed_accuracy_point:
    input:
        unpack(sweep_inputs),
    output:
        record=SWEEP_POINT,
    log:
        "logs/speed_accuracy/seed{seed}/{point}.log",
    benchmark:
        "results/studies/benchmarks/speed_accuracy/seed{seed}/{point}.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1  # two points run side by side on 2 cores (better throughput than 2 threads each)
    resources:
        mem_mb=4000,
        runtime=10 + CFG["train"]["iterations"] // 30,
    params:
        point=sweep_params,
    script:
        "../scripts/speed_accuracy_point.py"


# the sweep's points in one CSV; fig_speed_accuracy (physgs.report.trade) draws it
rule speed_accuracy:
    input:
        points=expand(SWEEP_POINT, seed=STUDY_SEEDS, point=SWEEP_POINTS),
    output:
        csv=report(
            TABLE.format(name="speed_accuracy", ext="csv"), category="4. Speed-accuracy trade"
        ),
    log:
        "logs/speed_accuracy/collect.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    script:
        "../scripts/speed_accuracy.py"


# The fit curve (issue "opponents, not foils"): each model's in-window and time-split PSNR against
# its training budget on one tree; the profile's own budget is the pipeline's job, not retrained.
rule fit_curve_point:
    input:
        observed=observed_input,
    output:
        record=FIT_POINT,
    log:
        "logs/fit_curve/{tree}/seed{seed}/{model}_it{iterations}.log",
    benchmark:
        "results/studies/benchmarks/fit_curve/{tree}/seed{seed}/{model}_it{iterations}.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=4000,
        runtime=lambda wc: 10 + int(wc.iterations) // 30,
    params:
        job=fit_point_params,
        series=lambda wc: wc.model,
    script:
        "../scripts/fit_curve_point.py"


# the diagnostic series: a field with Deformable-3DGS's window-normalised time, at the profile's
# budget, beside the time encoding the config chose
use rule fit_curve_point as fit_curve_window_point with:
    output:
        record=FIT_WINDOW_POINT,
    log:
        "logs/fit_curve/{tree}/seed{seed}/{model}_it{iterations}_windowtime.log",
    benchmark:
        "results/studies/benchmarks/fit_curve/{tree}/seed{seed}/{model}_it{iterations}_windowtime.tsv"
    params:
        job=fit_window_params,
        series=lambda wc: wc.model + _fit_curve.WINDOW_SERIES,


# the fit curve's points in one CSV; fig_fit_curve (physgs.report.trade) draws it
rule fit_curve:
    input:
        unpack(fit_curve_inputs),
    output:
        csv=report(TABLE.format(name="fit_curve", ext="csv"), category="4. Speed-accuracy trade"),
    log:
        "logs/fit_curve/collect.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        trees=_fit_curve.trees_of(CFG),
        models=FC_PROFILE_MODELS,
        seeds=STUDY_SEEDS,
        iterations=CFG["train"]["iterations"],
        n_train=CFG["testbed"]["n_train"],
        holdout_every=CFG["train"]["holdout_every"],
    script:
        "../scripts/fit_curve.py"
