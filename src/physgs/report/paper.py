"""Figures the source paper states ("Wind on Trees", CITATION.cff),
quoted once here so tables can print them beside what physgs measures."""

#: Section 4, null control: the median nearest-bone gap of each tree (percent).
NEAREST_BONE_GAP_PCT = {"sparse": 5.40, "medium": 0.40, "dense": 0.15}
#: Section 3, wind: natural frequencies span ~4.3x (0.35-1.5 Hz).
FREQUENCY_SPAN = 4.3
#: Section 3, geometry: animated bones per tree.
BONES = {"sparse": 22, "medium": 224, "dense": 562}

#: Table 1 (tab:psnr): PSNR, dB, on held-out views and beyond the training window,
#: (view, time) per tree and model id.
PSNR = {
    "sparse": {"static": (24.99, 25.16), "mlp": (25.45, 25.02), "mlp_wind": (26.39, 24.75),
               "d3dgs": (26.01, 24.25), "d3dgs_wind": (25.49, 24.53), "ours": (25.24, 25.42)},
    "medium": {"static": (25.35, 24.70), "mlp": (27.88, 23.07), "mlp_wind": (27.93, 23.53),
               "d3dgs": (27.66, 23.07), "d3dgs_wind": (27.75, 23.56), "ours": (26.37, 27.50)},
    "dense": {"static": (25.08, 24.09), "mlp": (26.59, 23.19), "mlp_wind": (26.44, 23.67),
              "d3dgs": (26.58, 22.65), "d3dgs_wind": (26.49, 23.31), "ours": (25.66, 26.14)},
}  # fmt: skip
#: Table tab:null: median omega error, %, of the trained model and of the untrained null.
NULL = {"sparse": (1.80, 4.56), "medium": (1.60, 1.77), "dense": (2.40, 1.56)}
#: Table tab:margin: ours' margin against MLP + wind, dB, at the training wind and two
#: departures.
MARGIN = {
    "sparse": (-1.42, -1.21, -0.61),
    "medium": (-0.60, 0.46, 1.67),
    "dense": (-0.03, -0.11, 0.75),
}
#: Section 4: the median fitted zeta per tree (the truth is 0.08).
ZETA = {"sparse": "0.095-0.102", "medium": "0.125-0.142", "dense": "0.125-0.142"}
#: The tree the paper's teaser figure shows (its clearest case).
TEASER_TREE = "medium"
#: Section 4: the true zeta of every bone.
ZETA_TRUE = 0.08
