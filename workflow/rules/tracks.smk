# The 2D-track control (docs/tracks.md): ours' oscillators fitted to point tracks of the
# training video instead of to pixels, so the physics and the renderer are told apart. `track` and
# `fit_tracks` read observed.npz only, like every training rule; `tracks_evaluate` reads the truth
# (the tracker's error, recovery beside ours' null, motion beyond the window and under unseen wind).


# one condition's training-camera video, tracked over the training window (observed only)
rule track:
    input:
        observed=OBSERVED,
    output:
        tracks=TRACKS,
    log:
        "logs/tracks/{tree}/c{condition}.log",
    benchmark:
        "results/benchmarks/tracks/{tree}/c{condition}.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        settings=_tracks.tracker_settings(CFG),
    script:
        "../scripts/track.py"


# testbed_seeds: the instance of training seed {seed}
use rule track as track_seeded with:
    input:
        observed=SEEDED_OBSERVED,
    output:
        tracks=SEEDED_TRACKS,
    log:
        "logs/tracks/{tree}/seed{seed}/c{condition}.log",
    benchmark:
        "results/benchmarks/tracks/{tree}/seed{seed}/c{condition}.tsv"


# the oscillators of each configuration of the tree fitted to the tracks of its conditions
# (observed only), one job per tree and seed: the configurations read the same files, and one
# process saves each of them the start-up of another; a K above the tracks kept stops here,
# naming the key
rule fit_tracks:
    input:
        unpack(fit_tracks_inputs),
    output:
        fits=tracks_outputs(TRACKS_FIT, TRACKS_CONFIGS),
    log:
        "logs/tracks/{tree}/seed{seed}/fit.log",
    benchmark:
        "results/benchmarks/tracks/{tree}/seed{seed}/fit.tsv"
    wildcard_constraints:
        tree="|".join(TREES),
        config="|".join(TRACKS_CONFIGS) or "(?!x)x",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        jobs=fit_tracks_params,
    script:
        "../scripts/fit_tracks.py"


# a damping testbed: the damping benchmark's configurations only
use rule fit_tracks as fit_tracks_damping with:
    output:
        fits=tracks_outputs(TRACKS_FIT, TRACKS_DAMPING_CONFIGS),
    wildcard_constraints:
        tree="|".join(DAMPING_TREES) or "(?!x)x",
        config="|".join(TRACKS_DAMPING_CONFIGS) or "(?!x)x",


# an evaluation (reads truth.npz) of each configuration of the tree, one job per tree and seed:
# tracker error, recovery through ours' matcher (with damping scores on the damping benchmark's
# testbeds), predicted tracks against the truth
rule tracks_evaluate:
    input:
        unpack(tracks_evaluate_inputs),
    output:
        scores=tracks_outputs(TRACKS_EVAL, TRACKS_CONFIGS),
        records=tracks_outputs(recovery_record("tracks"), TRACKS_CONFIGS),
    log:
        "logs/tracks/{tree}/seed{seed}/eval.log",
    benchmark:
        "results/benchmarks/tracks/{tree}/seed{seed}/eval.tsv"
    wildcard_constraints:
        tree="|".join(TREES),
        config="|".join(TRACKS_CONFIGS) or "(?!x)x",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=30,
    params:
        configs=lambda wildcards: tracks_configs(wildcards.tree),
        damping=tracks_evaluate_params,
    script:
        "../scripts/tracks_evaluate.py"


use rule tracks_evaluate as tracks_evaluate_damping with:
    output:
        scores=tracks_outputs(TRACKS_EVAL, TRACKS_DAMPING_CONFIGS),
        records=tracks_outputs(recovery_record("tracks"), TRACKS_DAMPING_CONFIGS),
    wildcard_constraints:
        tree="|".join(DAMPING_TREES) or "(?!x)x",
        config="|".join(TRACKS_DAMPING_CONFIGS) or "(?!x)x",


# an evaluation (reads truth.npz): the learned fields trained in the same configuration, at the
# control's tracked points (tab_tracks' best-field column; tab_null and tab_damping never need it)
rule tracks_fields:
    input:
        unpack(tracks_fields_inputs),
    output:
        scores=TRACKS_FIELDS,
    log:
        "logs/tracks/{tree}/seed{seed}/fields_{config}.log",
    benchmark:
        "results/benchmarks/tracks/{tree}/seed{seed}/fields_{config}.tsv"
    wildcard_constraints:
        config="|".join(TRACKS_CONFIGS) or "(?!x)x",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=30,
    script:
        "../scripts/tracks_fields.py"
