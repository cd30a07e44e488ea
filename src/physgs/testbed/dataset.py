"""The testbed dataset: build one tree end to end, save it, and load it back with validation.

Per tree two files: ``observed.npz`` (what models may read) and ``truth.npz`` (ground truth, never
an input of a training rule). Time: recorded frame j (0-based) is at t = j / fps seconds; the
stored wind and theta have L lead-in columns first, so column L + j is recorded frame j.

The ground truth starts at the periodic steady state of the (60 s periodic) wind, i.e. it is the
response to an infinitely long past; the L = 1.5 tau_max lead-in columns let a model that
integrates from rest at column 0 reach that steady state before the recorded window opens.
The damping variant ([`physgs.testbed.variant`][]) keeps that start state and records a gust
dropping to calm inside the training window; its lead-in follows the slowest decay rate,
min_b zeta_b omega_b.

Gaussian order: the observed Gaussians (``canonical_xyz``) are the mesh vertices in a seeded random
order, so their index carries no bone label (mesh order groups vertices by bone). The permutation
lives only in ``truth.npz``: Gaussian i is mesh vertex ``gaussian_vertex[i]``, and mesh vertex v is
Gaussian ``vertex_gaussian[v]``. Everything indexed by mesh vertex (``vertex_bone``,
``rest_vertices``, ``tip_vertices``, ``kinematics.pose_vertices``) stays in mesh order;
``kinematics.pose_gaussians`` poses in Gaussian order.
"""

from __future__ import annotations

import os
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from physgs.camera import Camera
from physgs.intermediate import load_npz
from physgs.testbed import kinematics, physics, scene, variant, weberpenn, wind as windmod
from physgs.testbed.mesh import TreeMesh, build_mesh, mesh_vertex_count

FORMAT_VERSION = 2  # 2: Gaussians in a seeded random order (gaussian_vertex), fill_height framing
REBUILD = "rebuild it with `snakemake --cores 2 testbed` (delete the bad file first)"


class DatasetError(RuntimeError):
    """A missing, corrupt or inconsistent dataset file; the message names the file and the fix."""


# --------------------------------------------------------------------------------------------
# Containers


@dataclass(frozen=True)
class Observed:
    """What a model may read. Shapes: C conditions, L lead-in frames, F = n_train + n_tail
    recorded frames, A held-out azimuths, M held-out frames, N vertices, H x W pixels.

    wind [C, L+F] float32 m/s (column L = recorded frame 0); vbar [C] m/s the condition's nominal
    mean speed (the drag forcing is v^2 - vbar^2); frames [C, F, H, W, 3] uint8; masks [C, F, H, W]
    bool; heldout_frames [A, M, H, W, 3]; heldout_masks [A, M, H, W]; canonical_xyz [N, 3] float32
    (m), vertex positions at recorded frame 0 of the training condition, in Gaussian order (a
    seeded random order of the mesh vertices; the permutation is in the truth file only).
    """

    fps: int
    n_train: int
    n_tail: int
    lead_in_frames: int
    conditions: np.ndarray
    vbar: np.ndarray
    wind: np.ndarray
    frames: np.ndarray
    masks: np.ndarray
    train_camera: Camera
    heldout_azimuths_deg: np.ndarray
    heldout_cameras: list
    heldout_frame_idx: np.ndarray
    heldout_frames: np.ndarray
    heldout_masks: np.ndarray
    background: np.ndarray
    canonical_xyz: np.ndarray


@dataclass(frozen=True)
class Truth:
    """Ground truth (never read by training). omega [B] rad/s, zeta [B], gain [B] (rad/s^2 per
    m^2/s^2), theta [C, L+F, B] rad (same columns as wind), bone_head / bone_tail [B, 3] m (rest),
    bone_parent [B] (-1 root), bone_level [B], bone_radius / bone_length [B] m, swing_axis [3],
    vertex_bone [N], rest_vertices [N, 3] m, faces [M, 3], vertex_colors [N, 3], tip_vertices [P]
    (all in mesh order: vertex indices), omega_clamped [B] bool, omega_c (calibration constant c in
    omega = c r / L^2), g0, fps, lead_in_frames, vbar [C] m/s; gaussian_vertex [N] (the mesh vertex
    of each observed Gaussian: canonical_xyz[i] is vertex gaussian_vertex[i]) and vertex_gaussian
    [N] (its inverse: the Gaussian of each mesh vertex)."""

    omega: np.ndarray
    zeta: np.ndarray
    gain: np.ndarray
    theta: np.ndarray
    bone_head: np.ndarray
    bone_tail: np.ndarray
    bone_parent: np.ndarray
    bone_level: np.ndarray
    bone_radius: np.ndarray
    bone_length: np.ndarray
    swing_axis: np.ndarray
    vertex_bone: np.ndarray
    rest_vertices: np.ndarray
    faces: np.ndarray
    vertex_colors: np.ndarray
    tip_vertices: np.ndarray
    omega_clamped: np.ndarray
    omega_c: float
    g0: float
    fps: int
    lead_in_frames: int
    vbar: np.ndarray
    gaussian_vertex: np.ndarray
    vertex_gaussian: np.ndarray


# --------------------------------------------------------------------------------------------
# Simulation (no rendering)


def _seed(seed: int, *parts) -> np.random.SeedSequence:
    return np.random.SeedSequence([int(seed)] + [zlib.crc32(str(p).encode()) for p in parts])


@dataclass(frozen=True)
class TreeSim:
    """One simulated tree: skeleton, mesh, true motion and the winds [C, L+F] m/s."""

    skeleton: weberpenn.Skeleton
    mesh: TreeMesh
    truth: Truth
    wind: np.ndarray  # [C, L+F] float32 m/s
    conditions: np.ndarray  # [C]


def tree_geometry(tb: dict, preset: dict, *, seed: int, tree: str):
    """The tree's skeleton and mesh, as the testbed builds them (no physics, wind or frames).

    Args:
        tb: the resolved ``testbed`` config section.
        preset: ``presets.<tree>``.
        seed: the run's seed.
        tree: the tree's name (seeds its streams).

    Returns:
        (Skeleton, TreeMesh): the bones and stems, and the mesh.

    Raises:
        PresetError: for an inconsistent preset.
        MeshBudgetError: when the vertex budget cannot hold the tubes.
    """
    skel = weberpenn.generate(preset, seed=seed, name=tree)
    leaves = preset.get("leaves") or {}
    mesh = build_mesh(
        skel,
        target_vertices=int(tb["vertices"][tree]),
        leaf_fraction=float(leaves.get("fraction", 0.0)),
        leaf_scale=float(leaves.get("scale", 0.1)),
        seed_seq=_seed(seed, tree, "mesh"),
    )
    return skel, mesh


def gaussian_count(tb: dict, preset: dict, skeleton, tree: str) -> int:
    """The Gaussians the tree has: its mesh's vertex count, which can fall a little short of
    ``testbed/vertices`` (385 of 400 on the quick sparse tree), computed without the mesh.

    Args:
        tb: the resolved ``testbed`` config section.
        preset: ``presets.<tree>``.
        skeleton (Skeleton): the tree's skeleton (``weberpenn.generate``).
        tree: the tree's name.

    Returns:
        The count.

    Raises:
        MeshBudgetError: when the vertex budget cannot hold the tubes.
    """
    return mesh_vertex_count(
        skeleton,
        target_vertices=int(tb["vertices"][tree]),
        leaf_fraction=float((preset.get("leaves") or {}).get("fraction", 0.0)),
    )


def simulate_tree(tb: dict, preset: dict, *, seed: int, tree: str) -> TreeSim:
    """Geometry, physics and wind for one tree (everything but the frames).

    ``tb["variant"]`` ([`physgs.testbed.variant`][physgs.testbed.variant]; default faithful)
    chooses a constant zeta and the unmodified wind, or per-bone zeta and a gust dropping to calm
    inside the training window.

    Args:
        tb: the resolved ``testbed`` config section.
        preset: ``presets.<tree>``.
        seed: the run's seed.
        tree: the tree's name (seeds its streams).

    Returns:
        The [`TreeSim`][physgs.testbed.dataset.TreeSim]: skeleton, mesh, truth and winds [C, L+F]
            (m/s).

    Raises:
        WindError: when the record is not shorter than the wind's period (or the period is not a
            whole number of frames), the wind speed reaches 0, or the transient starts before
            recorded frame 0.
        PresetError: for an inconsistent preset.
        MeshBudgetError: when the vertex budget cannot hold the tubes.
    """
    skel, mesh = tree_geometry(tb, preset, seed=seed, tree=tree)
    omega, c, clamped = physics.calibrate_omega(skel.radius, skel.length, tb["band_hz"])
    B = skel.n_bones
    # per-bone zeta (damping variant) from its own seeded stream: it changes nothing else
    zeta = variant.bone_zeta(tb, B, _seed(seed, tree, "zeta"))
    fps, F = int(tb["fps"]), int(tb["n_train"]) + int(tb["n_tail"])
    # the slowest decay rate zeta_b omega_b sets the lead-in (omega_min for a constant zeta)
    L = variant.lead_in_frames(omega, zeta, float(tb["lead_in_tau"]), fps)

    w = tb["wind"]
    wf = windmod.make_wind(
        v0=w["v0"],
        turbulence_intensity=w["turbulence_intensity"],
        f_lo_hz=w["f_lo_hz"],
        f_hi_hz=w["f_hi_hz"],
        seed_seq=_seed(seed, "wind"),
    )
    P = int(round(windmod.PERIOD_S * fps))  # the wind repeats every P frames
    if L + F >= P or abs(P - windmod.PERIOD_S * fps) > 1e-9:
        raise windmod.WindError(
            f"record of {(L + F) / fps:.1f} s must be shorter than the "
            f"{windmod.PERIOD_S:.0f} s wind period, which must be a whole number "
            "of frames; lower testbed.lead_in_tau or n_train/n_tail, or use an "
            "integer fps"
        )
    t = np.arange(-L, -L + P + 1) / fps  # one full period from the record start
    v_period = wf.speed(t)
    v = v_period[: L + F]
    if v_period.min() <= 0:
        raise windmod.WindError(
            f"wind speed reaches {v.min():.2f} m/s <= 0; lower "
            "testbed.wind.turbulence_intensity in config/trees.yaml"
        )
    transient = variant.transient_of(tb)
    if transient is not None:
        # the recorded wind (what models observe) carries the gust and the calm; the start
        # state below stays the periodic steady state of the unmodified wind, which is the
        # exact state at the record start because the transient begins inside the window
        if transient.start_s - transient.gust_s < 0:
            raise windmod.WindError(
                "testbed.damping.transient starts before recorded frame 0; "
                "raise start_s to at least gust_s in config/trees.yaml"
            )
        v = variant.shape_wind(v, t[: L + F], float(w["v0"]), transient)
    cond = np.asarray(tb["conditions"], dtype=np.float64)
    wind32 = (cond[:, None] * v[None, :]).astype(np.float32)  # [C, L+F]
    vbar = cond * float(w["v0"])
    u = physics.drag_forcing(wind32.astype(np.float64), vbar)  # [C, T], the wind models observe
    # the same float32 rounding over one whole period, to start at the periodic steady state
    vp32 = (cond[:, None] * v_period[None, :]).astype(np.float32).astype(np.float64)
    up = physics.drag_forcing(vp32, vbar)[:, :, None] * omega**2  # [C, P+1, B]
    x0 = physics.periodic_steady_state(omega, zeta, up, 1.0 / fps)
    unit = physics.simulate(
        omega, zeta, u[:, :, None] * omega[None, None, :] ** 2, 1.0 / fps, x0=x0
    )
    # "RMS swing" = RMS over bones and training frames of each bone's world angle (its own theta
    # plus its ancestors'), what a viewer sees; per-bone theta is smaller on deep chains.
    world = kinematics.cumulative_angle(skel.parent, unit[0, L : L + int(tb["n_train"])])
    rms = np.sqrt(np.mean(world**2))
    g0 = np.deg2rad(float(tb["rms_swing_deg"])) / rms
    theta = g0 * unit  # linear system: scaling the gain scales the response

    axis = kinematics.swing_axis(float(w["direction_deg"]))
    arm_levels = int(preset["armature_levels"])
    tip_cands = np.array(
        [mesh.stem_tip_vertex[i] for i, s in enumerate(skel.stems) if s.level == arm_levels - 1]
    )
    az = np.arctan2(mesh.vertices[tip_cands, 1], mesh.vertices[tip_cands, 0])
    order = tip_cands[np.argsort(az)]
    P = min(6, len(order))
    tips = order[np.linspace(0, len(order) - 1, P).round().astype(int)] if P else order
    # observed Gaussian order: its own seeded stream, so it changes nothing else in the tree
    gaussian_vertex = np.random.default_rng(_seed(seed, tree, "gaussian_order")).permutation(
        len(mesh.vertices)
    )
    vertex_gaussian = np.argsort(gaussian_vertex)

    truth = Truth(
        omega=omega,
        zeta=zeta,
        gain=g0 * omega**2,
        theta=theta,
        bone_head=skel.head,
        bone_tail=skel.tail,
        bone_parent=skel.parent,
        bone_level=skel.level,
        bone_radius=skel.radius,
        bone_length=skel.length,
        swing_axis=axis,
        vertex_bone=mesh.vertex_bone,
        rest_vertices=mesh.vertices,
        faces=mesh.faces,
        vertex_colors=mesh.vertex_colors,
        tip_vertices=tips,
        omega_clamped=clamped,
        omega_c=c,
        g0=float(g0),
        fps=fps,
        lead_in_frames=L,
        vbar=vbar,
        gaussian_vertex=gaussian_vertex,
        vertex_gaussian=vertex_gaussian,
    )
    return TreeSim(skel, mesh, truth, wind32, cond)


# --------------------------------------------------------------------------------------------
# Rendering


def swept_points(truth: Truth, chunk: int = 25) -> np.ndarray:
    """Vertices [K, 3] (m) of the convex hull of every posed vertex over every recorded frame of
    every condition (lead-in excluded): the tree's swept extent, as the framing needs it.

    Args:
        truth: the tree's ground truth.
        chunk: frames posed at a time (bounds memory, not the result).

    Returns:
        [K, 3] hull vertices, m.
    """
    L = truth.lead_in_frames
    th = truth.theta[:, L:].reshape(-1, truth.theta.shape[-1])
    return scene.convex_hull_points(
        kinematics.pose_vertices(truth, th[i : i + chunk]) for i in range(0, len(th), chunk)
    )


def build_dataset(tb: dict, preset: dict, *, seed: int, tree: str, progress: bool = True):
    """Simulate and render one tree.

    Args:
        tb: the resolved ``testbed`` config section.
        preset: ``presets.<tree>``.
        seed: the run's seed.
        tree: the tree's name.
        progress: show a progress bar while rendering.

    Returns:
        (tuple[dict, dict]): ``(observed, truth)``: the arrays of ``observed.npz`` and
            ``truth.npz`` by name, each with ``format_version``, for
            [`save_dataset`][physgs.testbed.dataset.save_dataset] (read back as
            [`Observed`][physgs.testbed.dataset.Observed] and
            [`Truth`][physgs.testbed.dataset.Truth]).

    Raises:
        FramingError: when ``testbed.fill_height`` is missing or does not fit every view.
        WindError: see [`simulate_tree`][physgs.testbed.dataset.simulate_tree].
    """
    sim = simulate_tree(tb, preset, seed=seed, tree=tree)
    tr = sim.truth
    L, fps = tr.lead_in_frames, tr.fps
    n_train, n_tail = int(tb["n_train"]), int(tb["n_tail"])
    F = n_train + n_tail
    if "fill_height" not in tb:
        raise scene.FramingError(
            "config key testbed.fill_height is missing (fraction of the training "
            "image height the swept tree spans, e.g. 0.9); add it to "
            "config/trees.yaml"
        )
    az = np.asarray(tb["heldout_azimuths_deg"], dtype=np.float64)
    cams = scene.frame_cameras(
        swept_points(tr),
        [0.0, *az],
        fov_deg=float(tb["fov_deg"]),
        resolution=int(tb["resolution"]),
        fill_height=float(tb["fill_height"]),
    )
    train_cam, held_cams = cams[0], cams[1:]
    # imported here: Embree and trimesh cost ~1 s of start-up, and most jobs only load datasets
    from physgs.testbed import raycast

    ss, bg = int(tb["supersample"]), np.asarray(tb["background"], dtype=np.float64)
    face_colors = tr.vertex_colors[tr.faces].mean(axis=1)
    held_idx = np.arange(0, n_train, int(tb["heldout_every"]))
    C, A, M, R = len(sim.conditions), len(held_cams), len(held_idx), int(tb["resolution"])

    frames = np.empty((C, F, R, R, 3), np.uint8)
    masks = np.empty((C, F, R, R), bool)
    hframes = np.empty((A, M, R, R, 3), np.uint8)
    hmasks = np.empty((A, M, R, R), bool)
    bar = tqdm(total=C * F + A * M, desc=f"render {tree}", disable=not progress, mininterval=2.0)
    rays = raycast.RayBundle(train_cam, ss)
    chunk = 25  # pose several frames per call (vectorised FK), render one by one
    for c in range(C):
        for j0 in range(0, F, chunk):
            Vs = kinematics.pose_vertices(tr, tr.theta[c, L + j0 : L + min(F, j0 + chunk)])
            for k, V in enumerate(Vs):
                rgb, alpha = raycast.render_mesh(V, tr.faces, face_colors, rays, bg)
                frames[c, j0 + k], masks[c, j0 + k] = raycast.to_uint8(rgb), alpha >= 0.5
                bar.update()
    Vs = kinematics.pose_vertices(tr, tr.theta[0, L + held_idx])  # [M, N, 3]
    for a, cam in enumerate(held_cams):
        rays = raycast.RayBundle(cam, ss)
        for m, V in enumerate(Vs):
            rgb, alpha = raycast.render_mesh(V, tr.faces, face_colors, rays, bg)
            hframes[a, m], hmasks[a, m] = raycast.to_uint8(rgb), alpha >= 0.5
            bar.update()
    bar.close()

    canonical = kinematics.pose_gaussians(tr, tr.theta[0, L]).astype(np.float32)
    observed = dict(
        format_version=FORMAT_VERSION,
        fps=fps,
        n_train=n_train,
        n_tail=n_tail,
        lead_in_frames=L,
        conditions=sim.conditions,
        vbar=tr.vbar,
        wind=sim.wind,
        frames=frames,
        masks=masks,
        heldout_azimuths_deg=az,
        heldout_frame_idx=held_idx,
        heldout_frames=hframes,
        heldout_masks=hmasks,
        background=bg,
        canonical_xyz=canonical,
        **{f"train_camera_{k}": v for k, v in train_cam.to_dict().items()},
        **{
            f"heldout_camera_{k}": np.stack([cm.to_dict()[k] for cm in held_cams])
            for k in ("viewmat", "intrinsics", "size", "near")
        },
    )
    truth = {k: getattr(tr, k) for k in Truth.__dataclass_fields__}
    truth["format_version"] = FORMAT_VERSION
    return observed, truth


# --------------------------------------------------------------------------------------------
# Save / load


def save_dataset(observed: dict, truth: dict, observed_path, truth_path) -> None:
    """Write both files; neither appears unless both were written completely.

    Args:
        observed: the observed arrays (``np.savez_compressed`` keywords).
        truth: the truth arrays.
        observed_path (str | Path): the observed ``.npz``.
        truth_path (str | Path): the truth ``.npz``.
    """
    parts = []
    try:
        for arrays, p in ((observed, Path(observed_path)), (truth, Path(truth_path))):
            p.parent.mkdir(parents=True, exist_ok=True)
            tmp = p.with_name(p.name + ".part")
            parts.append((tmp, p))
            with open(tmp, "wb") as f:
                np.savez_compressed(f, **arrays)
        for tmp, p in parts:
            os.replace(tmp, p)
    finally:
        for tmp, _ in parts:
            if tmp.exists():
                tmp.unlink()


def _open(path: Path | str, required: tuple[str, ...]) -> dict:
    path = Path(path)

    def error(problem: str, detail: str) -> DatasetError:
        if problem == "missing":
            return DatasetError(
                f"dataset file {path} does not exist; build it with "
                "`snakemake --cores 2 testbed` (or the matching results/testbed target)"
            )
        what = {
            "corrupt": f"is corrupt ({detail})",
            "lacks": f"lacks {detail}: it is from another version or incomplete",
        }[problem]
        return DatasetError(f"dataset file {path} {what}; {REBUILD}")

    d = load_npz(path, required, error)
    if int(d.get("format_version", -1)) != FORMAT_VERSION:
        raise DatasetError(
            f"dataset file {path} has format_version {d.get('format_version')}, "
            f"expected {FORMAT_VERSION}; {REBUILD}"
        )
    return d


def _check(path, ok: bool, what: str):
    if not ok:
        raise DatasetError(f"dataset file {path} is inconsistent: {what}; {REBUILD}")


OBSERVED_KEYS = (
    "fps",
    "n_train",
    "n_tail",
    "lead_in_frames",
    "conditions",
    "vbar",
    "wind",
    "frames",
    "masks",
    "train_camera_viewmat",
    "train_camera_intrinsics",
    "train_camera_size",
    "train_camera_near",
    "heldout_azimuths_deg",
    "heldout_camera_viewmat",
    "heldout_camera_intrinsics",
    "heldout_camera_size",
    "heldout_camera_near",
    "heldout_frame_idx",
    "heldout_frames",
    "heldout_masks",
    "background",
    "canonical_xyz",
)


#: what each array of observed.npz holds (numpy's ``dtype.kind``): pixels uint8 (checked
#: exactly), masks "b", counts, indices and sizes "i" or "u", everything else real numbers
#: ("f", "i" or "u"; floats must all be finite)
OBSERVED_KINDS = {
    **dict.fromkeys(("frames", "heldout_frames"), "u1"),
    **dict.fromkeys(("masks", "heldout_masks"), "b"),
    **dict.fromkeys(
        (
            "fps",
            "n_train",
            "n_tail",
            "lead_in_frames",
            "heldout_frame_idx",
            "train_camera_size",
            "heldout_camera_size",
        ),
        "iu",
    ),
}


def _check_arrays(path, d: dict) -> None:
    """Every array of observed.npz is of its kind (``OBSERVED_KINDS``; real numbers otherwise)
    and finite: a float array with NaN in place of pixels fails here, not in the renderer's checks."""
    for k in OBSERVED_KEYS:
        a = np.asarray(d[k])
        want = OBSERVED_KINDS.get(k, "fiu")
        if a.dtype.kind in "fc" and not np.isfinite(a).all():
            n = int(np.size(a) - np.isfinite(a).sum())
            _check(path, False, f"{k} holds {n} NaN or infinite value(s) (dtype {a.dtype})")
        ok = a.dtype == np.uint8 if want == "u1" else a.dtype.kind in want
        expected = {"u1": "uint8", "b": "bool", "iu": "integer", "fiu": "real numbers"}[want]
        _check(path, ok, f"{k} has dtype {a.dtype}, expected {expected}")


def load_observed(path: Path | str) -> Observed:
    """Load and validate ``observed.npz``.

    Args:
        path: the file.

    Returns:
        The [`Observed`][physgs.testbed.dataset.Observed] dataset.

    Raises:
        DatasetError: the file is missing or invalid: an array of the wrong dtype, NaN or
            infinity in any array, shapes that disagree (the message names the file, the array
            and the fix).
    """
    d = _open(path, OBSERVED_KEYS)
    _check_arrays(path, d)
    C, F = len(d["conditions"]), int(d["n_train"]) + int(d["n_tail"])
    L = int(d["lead_in_frames"])
    _check(path, d["wind"].shape == (C, L + F), f"wind shape {d['wind'].shape} != ({C}, {L + F})")
    _check(
        path,
        d["frames"].shape[:2] == (C, F) and d["frames"].dtype == np.uint8,
        f"frames shape {d['frames'].shape} / dtype {d['frames'].dtype}",
    )
    _check(path, d["masks"].shape == d["frames"].shape[:4], "masks do not match frames")
    A = len(d["heldout_azimuths_deg"])
    _check(
        path,
        d["heldout_camera_viewmat"].shape == (A, 4, 4),
        "held-out cameras do not match azimuths",
    )
    _check(
        path,
        d["heldout_frames"].shape[:2] == (A, len(d["heldout_frame_idx"])),
        "held-out frames do not match azimuths x frame indices",
    )
    _check(
        path,
        d["heldout_masks"].shape == d["heldout_frames"].shape[:4],
        "held-out masks do not match held-out frames",
    )
    _check(
        path,
        d["canonical_xyz"].ndim == 2 and d["canonical_xyz"].shape[1] == 3,
        "canonical_xyz not [N, 3]",
    )
    cam = Camera.from_dict(
        {k: d[f"train_camera_{k}"] for k in ("viewmat", "intrinsics", "size", "near")}
    )
    held = [
        Camera.from_dict(
            {k: d[f"heldout_camera_{k}"][a] for k in ("viewmat", "intrinsics", "size", "near")}
        )
        for a in range(A)
    ]
    return Observed(
        fps=int(d["fps"]),
        n_train=int(d["n_train"]),
        n_tail=int(d["n_tail"]),
        lead_in_frames=L,
        conditions=d["conditions"],
        vbar=d["vbar"],
        wind=d["wind"],
        frames=d["frames"],
        masks=d["masks"],
        train_camera=cam,
        heldout_azimuths_deg=d["heldout_azimuths_deg"],
        heldout_cameras=held,
        heldout_frame_idx=d["heldout_frame_idx"],
        heldout_frames=d["heldout_frames"],
        heldout_masks=d["heldout_masks"],
        background=d["background"],
        canonical_xyz=d["canonical_xyz"],
    )


def load_truth(path: Path | str) -> Truth:
    """Load and validate ``truth.npz``.

    Args:
        path: the file.

    Returns:
        The [`Truth`][physgs.testbed.dataset.Truth].

    Raises:
        DatasetError: the file is missing or invalid (the message names the file and the fix).
    """
    keys = tuple(Truth.__dataclass_fields__)
    d = _open(path, keys)
    B = len(d["omega"])
    _check(
        path, d["theta"].ndim == 3 and d["theta"].shape[2] == B, f"theta shape {d['theta'].shape}"
    )
    _check(
        path, d["bone_head"].shape == (B, 3) and len(d["bone_parent"]) == B, "bone arrays disagree"
    )
    _check(
        path,
        len(d["vertex_bone"]) == len(d["rest_vertices"]),
        "vertex_bone does not match rest_vertices",
    )
    _check(
        path,
        bool((d["vertex_bone"] >= 0).all() and (d["vertex_bone"] < B).all()),
        "vertex_bone out of range",
    )
    N = len(d["rest_vertices"])
    gv, vg = d["gaussian_vertex"], d["vertex_gaussian"]
    _check(
        path,
        gv.shape == (N,)
        and vg.shape == (N,)
        and np.array_equal(np.sort(gv), np.arange(N))
        and np.array_equal(gv[vg], np.arange(N)),
        "gaussian_vertex is not a permutation of the vertices with inverse vertex_gaussian",
    )
    scalars = {"omega_c": float, "g0": float, "fps": int, "lead_in_frames": int}
    return Truth(**{k: scalars[k](d[k]) if k in scalars else d[k] for k in keys})
