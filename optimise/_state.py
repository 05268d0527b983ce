"""The state of the design search on steady running, and its checkpoint.

After every iteration the whole state (iterates, optimiser and multiplier states, continuation
states, history, the envelope's active set) is written atomically to
DIR/checkpoint.npz, data only (`jaxbearing.io.save_tree`: arrays in `.npz`, structure as JSON),
and checked for type and shape against a fresh state when read back. A `checkpoint.pkl` of an
older version is refused, never unpickled: a pickle can run code. A checkpoint resumes only a
search whose `fingerprint` (everything that decides its result) is the same.
"""

from __future__ import annotations

import dataclasses
import hashlib
import pathlib

import jax
import numpy as np

from jaxbearing import UserInputError
from jaxbearing.io import TreeFileError, check_like, load_tree, save_tree

from ._envelope import Envelope
from ._lagrangian import Hyper
from ._problem import DesignProblem
from ._settings import Choice, SteadySettings

CHECKPOINT = "checkpoint.npz"
#: the name of the pickled checkpoints of older versions: refused, never loaded
LEGACY_CHECKPOINT = "checkpoint.pkl"
#: version of the measured objective, margins and state layout, part of a checkpoint's
#: fingerprint: a checkpoint of another version is refused, not resumed
MEASUREMENT_VERSION = 8


@jax.tree_util.register_dataclass
@dataclasses.dataclass
class History:
    """Per iteration, per start: what the search measured (lists of arrays, one per iteration)."""

    x: list = dataclasses.field(default_factory=list)  # (S, n) designs [SI]
    objective: list = dataclasses.field(default_factory=list)  # (S,) [GPa m/s, or W: `Statistic.shown`]
    ci: list = dataclasses.field(default_factory=list)  # (S, 2)
    gradient: list = dataclasses.field(default_factory=list)  # (S, n) per unit box
    gradient_stderr: list = dataclasses.field(default_factory=list)  # (S, n)
    #: (S, 5 + L): the static margins and the dynamic corner margin [m], then the margins of
    #: the L limits of `SteadySettings.limits` in their own units (Lambda; K)
    margins: list = dataclasses.field(default_factory=list)
    wall_s: list = dataclasses.field(default_factory=list)  # (S,)
    simulated_ms: list = dataclasses.field(default_factory=list)  # (S,)
    points_simulated: list = dataclasses.field(default_factory=list)  # (S, K) bool
    #: (S,) the largest upper 95 % bound of the corner-contact risk per revolution over the points
    corner_risk: list = dataclasses.field(default_factory=list)

    def append(self, rows: dict) -> None:
        """One iteration's rows (a list per field, one entry per start)."""
        for f in dataclasses.fields(self):
            getattr(self, f.name).append(rows[f.name])

    def as_arrays(self) -> dict[str, np.ndarray]:
        """Every field as one array with leading axes (iteration, start)."""
        return {f.name: np.asarray(getattr(self, f.name)) for f in dataclasses.fields(self)}

    def __len__(self) -> int:
        return len(self.x)


@jax.tree_util.register_dataclass
@dataclasses.dataclass
class SearchState:
    """Everything the search needs to continue after iteration `iteration` (-1: none yet)."""

    iteration: int
    u: np.ndarray  # (S, n) the next iterates, scaled
    opt: list  # per start: the optimiser's state
    lam: np.ndarray  # (S, 5 + L) multipliers
    chains: list  # per start: None or per operating point the settled states to continue from
    history: History
    evaluations: int  # settled ensembles run
    envelope: Envelope


def fingerprint(problem: DesignProblem, settings: SteadySettings, hyper: Hyper, starts) -> str:
    """A hash of everything that decides the search's path (for resuming): the bearing and
    operating points, bounds, constraints, envelope, measurement settings, step sizes, starts.
    Not the worker count, nor which of the tied designs is returned (`SteadySettings.choose`
    picks from the finished history), so a finished search resumed with another choice
    returns that choice's design without simulating again."""
    leaves = [
        np.asarray(v).tobytes()
        for v in jax.tree_util.tree_leaves((problem.bearing, problem.operating, problem.point_bearings))
    ]
    text = repr(
        (
            MEASUREMENT_VERSION,
            problem.bounds,
            problem.aggregate,
            problem.temperature,
            problem.tighten,
            problem.flange_load,
            problem.min_clearance,
            np.asarray(problem.weights).tolist(),
            # the processes do not change the path, nor does the choice among the tied designs
            dataclasses.replace(settings, workers=0, choose=Choice.SAFEST),
            hyper,
            np.asarray(starts).tolist(),
        )
    )
    h = hashlib.sha256(text.encode())
    for leaf in leaves:
        h.update(leaf)
    return h.hexdigest()


def save_checkpoint(path: pathlib.Path, key: str, state) -> None:
    """`state` (data only: `jaxbearing.io.save_tree`, `.npz` and JSON) with its fingerprint
    `key`, atomically."""
    save_tree(path, {"fingerprint": key, "state": jax.tree_util.tree_map(np.asarray, state)})


def load_checkpoint(path: pathlib.Path) -> dict:
    """A checkpoint written by `save_checkpoint`; one line naming the file for anything else
    (a pickle is refused, never unpickled)."""
    try:
        return load_tree(path, what="checkpoint")
    except TreeFileError as exc:
        raise UserInputError(f"{exc}; remove it to start afresh") from None


def refuse_legacy(path: pathlib.Path) -> None:
    """One line, and nothing loaded, where a pickled checkpoint of an older version lies."""
    if path.exists():
        raise UserInputError(
            f"{path}: a pickled checkpoint of an older version (not loaded: a pickle can run "
            "code); remove it to start afresh"
        )


def checked_state(path: pathlib.Path, state, template: SearchState, num_iterations: int) -> SearchState:
    """`state` read from a checkpoint, checked for type and shape against a fresh `template`."""

    def bad(why: str):
        return UserInputError(f"{path}: not a checkpoint of this search ({why}); remove it to start afresh")

    if not isinstance(state, SearchState):
        raise bad("its fields differ")
    it = state.iteration
    it = int(it) if np.ndim(it) == 0 and np.asarray(it).dtype.kind in "iu" else None
    if it is None or not -1 <= it <= num_iterations:
        raise bad(f"iteration {state.iteration!r}")
    state.iteration = it
    check_like(state.u, template.u, path, "checkpoint")
    check_like(state.lam, template.lam, path, "checkpoint")
    check_like(state.opt, jax.tree_util.tree_map(np.asarray, template.opt), path, "checkpoint")
    if not isinstance(state.chains, list) or len(state.chains) != len(template.chains):
        raise bad("continuation states")
    if not isinstance(state.history, History):
        raise bad("history")
    if any(not isinstance(v, list) or len(v) != it + 1 for v in vars(state.history).values()):
        raise bad("history length")
    if not isinstance(state.envelope, Envelope):
        raise bad("envelope")
    for name, v in vars(template.envelope).items():
        check_like(getattr(state.envelope, name), v, path, "checkpoint")
    return state


def resumed_state(
    path: pathlib.Path | None, key: str, fresh: SearchState, num_iterations: int
) -> SearchState:
    """The checkpoint at `path` when it belongs to this search (fingerprint `key`), else
    `fresh`; one line for a checkpoint of another search or anything that is not one."""
    if path is None:
        return fresh
    refuse_legacy(path.with_name(LEGACY_CHECKPOINT))
    if not path.exists():
        return fresh
    saved = load_checkpoint(path)
    if not isinstance(saved, dict) or saved.get("fingerprint") != key:
        raise UserInputError(
            f"{path}: a checkpoint of a search with other settings; remove it or choose another --out to start afresh"
        )
    return checked_state(path, saved.get("state"), fresh, num_iterations)
