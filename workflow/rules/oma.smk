# Output-only modal analysis (docs/blind.md): SSI-cov of the training video's dense flow.
# `oma_identify` reads observed.npz's frames only (never the wind); `oma_recovery` reads the
# truth (the matcher's bones), and so does the report's `fig_stabilisation` (the true
# frequencies drawn, never used).


rule oma_identify:
    input:
        observed=observed_input,
    output:
        modes=OMA_MODES,
    log:
        "logs/oma/{tree}/seed{seed}/modes_{config}.log",
    benchmark:
        "results/benchmarks/oma/{tree}/seed{seed}/modes_{config}.tsv"
    wildcard_constraints:
        config="|".join(OMA_CONFIGS) or "(?!x)x",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=10,
    params:
        settings=oma_identify_params,
    script:
        "../scripts/oma_identify.py"


# an evaluation (reads truth.npz): the modes mapped to parts, through ours' matcher
rule oma_recovery:
    input:
        unpack(oma_recovery_inputs),
    output:
        record=recovery_record("oma"),
    log:
        "logs/oma/{tree}/seed{seed}/recovery_{config}.log",
    benchmark:
        "results/benchmarks/oma/{tree}/seed{seed}/recovery_{config}.tsv"
    wildcard_constraints:
        config="|".join(OMA_CONFIGS) or "(?!x)x",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        job=oma_recovery_params,
        damping=recovery_damping_params,
    script:
        "../scripts/oma_recovery.py"


# every record and figure of the analysis (part of `all`; tab_recovery and tab_damping read the
# records)
rule oma:
    input:
        expand(recovery_record("oma"), tree=TESTBEDS, seed=SEEDS, config=OMA_CONFIGS),
        # each tree's stabilisation diagram (an output: physgs.report.stabilisation)
        expand(FIGURE, name="fig_stabilisation", ext=("pdf", "png")) if OMA_CONFIGS else [],
