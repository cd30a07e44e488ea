"""The caption of every figure the record shows: what it shows, how to read it, and its seeds.

What a figure shows and how to read it is written once per figure here (it describes the drawing
code, not a result); its seeds come from its output's declaration
(``physgs.report.outputs.OUTPUTS[name].seeds``, else the caption's own ``seeds``) and the record's
stamp, so a caption never retypes a number of the run. ``FIGURES`` orders the figures as a
results section reads them: the headline comparison first, the testbed last.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from physgs.report.outputs import OUTPUTS


@dataclass(frozen=True)
class Caption:
    """One figure's caption: ``pattern`` its name (``{tree}`` standing for a tree), ``title`` a
    few words, ``shows`` what is drawn (every colour, band, line and unit), ``read`` how to read
    it, ``seeds`` its seed scope when it is not a report output (``physgs.report.output.SEEDS``)."""

    pattern: str
    title: str
    shows: str
    read: str
    seeds: str = "first"

    def match(self, name: str) -> str | None:
        """The tree of figure ``name`` when it is this figure.

        Args:
            name: a figure's file stem.

        Returns:
            The tree, '' when the pattern has none, None when ``name`` is another figure.
        """
        rx = "^" + re.escape(self.pattern).replace(r"\{tree\}", "(?P<tree>[a-z0-9_]+?)") + "$"
        m = re.match(rx, name)
        return None if m is None else m.groupdict().get("tree") or ""


#: The figures in reading order.
FIGURES: tuple[Caption, ...] = (
    Caption(
        "fig_temporal",
        "PSNR over time at the training camera",
        "Per-frame PSNR (dB) of each model's render at the training camera and the training wind, "
        "one panel per tree: each model's mean over the seeds as a line, a band of its colour "
        "from its lowest to its highest seed; the dashed grey line is the static pose, the black "
        "dotted line the true-motion ceiling (the renderer driven by the true motion). The grey "
        "shaded region right of the dotted vertical line is beyond the training window (the time "
        "split).",
        "In the shaded region a model above the dashed static pose extrapolates the motion; one "
        "below it does worse than standing still.",
    ),
    Caption(
        "fig_results",
        "Renders against the ground truth",
        "One representative frame per tree and split (rows: unseen time, unseen view, unseen "
        "wind), rendered by each model (columns) beside the ground truth; each panel's PSNR in dB "
        "against the ground truth. The frame is the one whose gap between ours and the best "
        "learned field is closest to the split's mean gap. Colour of a PSNR: green, ours where it "
        "is the best of its row; orange, a model that beats ours in its row; black otherwise.",
        "Read across a row: orange numbers are where ours loses on that split and tree.",
    ),
    Caption(
        "fig_teaser",
        "A branch tip and the canopy centroid",
        "Top: the path in the image (x, y in px; y down) of the branch tip the ground truth moves "
        "most, for the ground truth and each model drawn: grey through the training window, blue "
        "beyond it, the ground truth dotted beside each model. Bottom: the canopy centroid's "
        "error (px) per frame at the training wind and at an unseen wind, each model's mean in "
        "its key; the dotted vertical line ends the training window.",
        "A model that tracks the motion keeps its blue path on the dotted ground truth and its "
        "error flat after the window.",
    ),
    Caption(
        "fig_damping",
        "Damping recovery",
        "The damping benchmark. Left: each part's recovered damping ratio (no unit) per tree "
        "(colour), configuration (marker) and prior (filled: ours; hollow: the chained prior), "
        "jittered sideways for display; the black bar is the median of its group, the dashed line "
        "the true damping ratio, a row of points at the top sits on the fitting bound (the "
        "largest damping ratio the fit may take, `models.ours.zeta` in config/trees.yaml; dotted, "
        "its value in the key): those parts ran into the bound, so their damping is not "
        "estimated. Right: each part's decay rate (damping ratio times natural frequency, 1/s) "
        "against its natural frequency (rad/s), both axes logarithmic; the dashed line is the "
        "truth (decay rate = true damping ratio x frequency).",
        "Points on the dashed lines recover damping; a cloud above them over-damps. A cloud "
        "steeper or flatter than the dashed line on the right has the wrong dependence on "
        "frequency.",
    ),
    Caption(
        "fig_parts",
        "The priors' parts",
        "Each tree's canonical Gaussians seen from the side (x right, height z up, metres), "
        "coloured by their part in each prior's segmentation (one panel per prior); each part's "
        "pivot is a black dot, joined to its parent's pivot where the prior chains its parts. "
        "Each panel's title gives the segmentation's purity (share of Gaussians in their part's "
        "majority bone).",
        "Parts that follow the branches (high purity) can move as the bones do; parts that cut "
        "across branches mix bones of different frequencies.",
    ),
    Caption(
        "fig_tracks",
        "The 2D-track control",
        "Each tree's training-camera frame 0 (axes in px of the frame) under the paths of the "
        "point tracks through the training window, each path's seed position a dot; coloured by "
        "the track's part in the control's first configuration, grey where the track was not "
        "fitted or its part has no estimate. Each panel's title: the tracks, the share of frame "
        "0's tracks kept to the window's end, and the tracks in parts with an estimate.",
        "Long coloured paths on the crown are the motion the control fits its oscillators to; a "
        "crown mostly grey gives the control little to fit.",
    ),
    Caption(
        "fig_stabilisation",
        "Output-only modal analysis",
        "Each tree's stabilisation diagram of its training window (one column a tree): every pole "
        "found (frequency in Hz, horizontal) at every model order tried (vertical), blue where "
        "stable across orders, grey where not; the identified modes as red vertical lines, each "
        "with its 95% frequency interval (Hz) as an error bar along the top. The strip below "
        "marks the bones' true frequencies (Hz); they are drawn, never used to select a mode.",
        "Columns of stable poles are modes the video shows; where they sit over the strip's "
        "ticks, the analysis finds the bones' frequencies without a model of the tree.",
    ),
    Caption(
        "testbed_{tree}",
        "The {tree} testbed",
        "The synthetic {tree} tree: its bones in metres (height against downwind), coloured by "
        "natural frequency (Hz); the histogram of the bones' natural frequencies (Hz), all bones "
        "and those whose own motion moves at least 1 px in the image; three bones' true angle "
        "(deg) over time (s) at the training wind, the lead-in before 0 s and the tail after the "
        "red line; and renders from the training camera, at an unseen wind, beyond the window and "
        "from two unseen views. The title line gives the testbed's statistics.",
        "A wide spread of frequencies is what a recovery must resolve; bones under 1 px of motion "
        "cannot be recovered from the video.",
        seeds="none",
    ),
    Caption(
        "fig_speed_accuracy",
        "The speed-accuracy trade",
        "Ours on the sweep's tree, one knob at a time away from the profile's setting (image "
        "side, iterations, RK4 substeps, K, Gaussians). Left: PSNR on the time split (dB) against "
        "the wall time per point (s, log); right: the median relative omega error over trusted "
        "parts (%) against the same time. One line per knob through its values, points the mean "
        "over the seeds with the sd as error bars on both axes; the profile's setting starred. On "
        "the right, the untrained null of the profile's K: its median (line) and the central 95% "
        "of its draws (band).",
        "A knob whose line climbs to the left buys accuracy cheaply; a recovery point inside the "
        "null's band is chance.",
    ),
    Caption(
        "fig_fit_curve",
        "Fit against training budget",
        "Each model trained at each budget, a row of panels per tree: the in-window fit PSNR (dB, "
        "trained frames) and the time-split PSNR (dB, the tail) against training iterations "
        "(log), and the fit against training wall time (s, log); points the mean over the seeds, "
        "error bars the sd. The static pose (dashed) and the true-motion ceiling (dotted) at the "
        "profile's budget are horizontal lines; the profile's budget is starred; a field trained "
        "with Deformable-3DGS's window-normalised time is drawn as open diamonds in its colour.",
        "A curve still climbing at the profile's budget means that model is under-trained there; "
        "one flat across budgets has converged.",
    ),
    Caption(
        "fig_fit_vs_extrapolation",
        "Fitting the window against extrapolating beyond it",
        "Along each model's fit curve, one panel per tree: its gain over the static pose beyond "
        "the window (time-split PSNR minus static's, dB) against its in-window fraction of the "
        "true-motion ceiling's gain over static (trained frames); one line through its budgets "
        "(seed means; each seed's points faint), the profile's budget starred. Dotted: the fit "
        "bar; dashed: no gain over static.",
        "A line falling to the right means fitting the window more made that model extrapolate "
        "worse: the trade the paper's headline hinges on; a line rising to the right means the "
        "opposite.",
    ),
    Caption(
        "testbed_{tree}_damping",
        "The {tree} damping testbed",
        "The damping benchmark's variant of the {tree} tree, drawn as its testbed (bones by "
        "natural frequency in Hz, the frequency histogram, three bones' true angles in deg over "
        "time in s, renders).",
        "The same reading as the testbed's; this variant is the one damping is recovered on.",
        seeds="none",
    ),
)


def find(name: str) -> tuple[int, Caption, str]:
    """The caption of figure ``name``, its place in ``FIGURES`` and its tree.

    Per-tree patterns are tried after the plain names, the longer first, so that
    ``testbed_medium_damping`` is the damping testbed's, not a tree ``medium_damping``'s.

    Args:
        name: the figure's file stem.

    Returns:
        ``(index, caption, tree)``.

    Raises:
        KeyError: naming a figure without a caption.
    """
    for i in sorted(
        range(len(FIGURES)), key=lambda i: ("{" in FIGURES[i].pattern, -len(FIGURES[i].pattern))
    ):
        tree = FIGURES[i].match(name)
        if tree is not None:
            return i, FIGURES[i], tree
    raise KeyError(f"figure {name!r} has no caption: add it to physgs.report.captions.FIGURES")


def _seeds(what: str, seeds: list[int]) -> str:
    """The seeds a figure of seed scope ``what`` draws, in words."""
    if what == "all" and len(seeds) == 1:
        return f"training seed {seeds[0]} (the run's one seed)"
    if what == "all":
        return f"mean over training seeds {', '.join(map(str, seeds))}"
    if what == "first":
        return f"training seed {seeds[0]} (the first of the run's {len(seeds)})"
    return "the testbed itself: no training seed" if what == "none" else "the studies' seeds"


def caption(name: str, seeds: Sequence[int]) -> str:
    """The Markdown caption of figure ``name`` in a run of training ``seeds``.

    Args:
        name: the figure's file stem.
        seeds: the run's training seeds (its stamp's).

    Returns:
        One paragraph: title, what it shows, how to read it, its seeds.
    """
    _, c, tree = find(name)
    what = OUTPUTS[c.pattern].seeds if c.pattern in OUTPUTS else c.seeds
    title, shows, read = (s.format(tree=tree) for s in (c.title, c.shows, c.read))
    return (
        f"**Figure: {title}** (`{name}`). {shows} "
        f"*How to read it:* {read} *Seeds:* {_seeds(what, list(seeds))}."
    )


def order(names: Sequence[str], trees: Sequence[str] = ()) -> list[str]:
    """``names`` in reading order: by their caption's place in ``FIGURES``, then per-tree
    figures in the run's order of trees, then by name.

    Args:
        names: figure file stems.
        trees: the run's trees, in order.

    Returns:
        The same names, ordered.

    Raises:
        KeyError: naming a figure without a caption.
    """
    rank = {t: i for i, t in enumerate(trees)}

    def key(n: str) -> tuple[int, int, str]:
        i, _, tree = find(n)
        return i, rank.get(tree, len(rank)), n

    return sorted(names, key=key)
