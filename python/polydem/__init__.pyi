"""Type stubs of the polydem package (the native module polydem._polydem)."""

from os import PathLike
from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Union, final

from typing_extensions import disjoint_base

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "CheckpointError",
    "ContactResult",
    "ConvexPolyhedron",
    "Ellipsoid",
    "Scene",
    "SceneError",
    "Shape",
    "Simulation",
    "Sphere",
    "StepError",
    "__version__",
    "contact",
    "bodies",
    "contact_batch",
    "contact_oracle",
    "find_checkout",
    "rockfill",
    "scene_to_toml",
    "validate",
]

from .scene_builder import bodies as bodies
from .validation import find_checkout as find_checkout, validate as validate

_ArrayLike = npt.ArrayLike
_FloatArray = npt.NDArray[np.float64]
_Pose = Tuple[_ArrayLike, _ArrayLike]
"""(position[3] in m, quaternion[4] as w, x, y, z)."""
_StrPath = Union[str, PathLike]

class SceneError(ValueError):
    """A scene that cannot be read or built; the message is the engine's (file:line: field: problem)."""

    path: str
    line: Optional[int]
    field: Optional[str]

class CheckpointError(ValueError):
    """A checkpoint file that cannot be read (not a checkpoint, another version, truncated, corrupt)."""

class StepError(RuntimeError):
    """A step that failed (a non-finite state, an invalid time step); names the body and step."""

@disjoint_base
class Shape:
    """A bounded convex shape. Mass properties per unit density, in the frame the shape was given in."""

    @property
    def volume(self) -> float:
        """Volume (m³)."""
    @property
    def centroid(self) -> _FloatArray:
        """Centroid in the shape's input frame (m), shape (3,)."""
    @property
    def principal_moments(self) -> _FloatArray:
        """Principal moments of inertia per unit density (m⁵), ascending, shape (3,)."""
    @property
    def principal_axes(self) -> _FloatArray:
        """3×3 array whose column k is the axis of principal_moments[k], in the input frame."""
    @property
    def bounding_radius(self) -> float:
        """Radius of the bounding sphere about the centroid (m)."""

@final
class ConvexPolyhedron(Shape):
    """A convex polyhedron: the convex hull of a point cloud."""

    @staticmethod
    def from_points(points: _ArrayLike) -> ConvexPolyhedron:
        """The hull of an (N, 3) array of finite points (N ≥ 4, not coplanar); ValueError otherwise."""
    @property
    def vertices(self) -> _FloatArray:
        """Hull vertices in the input frame, shape (N, 3) (a copy)."""
    @property
    def num_faces(self) -> int:
        """Number of (polygonal) faces."""

@final
class Sphere(Shape):
    """A sphere of the given radius (m) centred at its origin."""

    def __new__(cls, radius: float) -> Sphere: ...
    @property
    def radius(self) -> float:
        """Radius (m)."""

@final
class Ellipsoid(Shape):
    """An ellipsoid with semi-axes a, b, c (m) along its x, y, z axes."""

    def __new__(cls, a: float, b: float, c: float) -> Ellipsoid: ...
    @property
    def semi_axes(self) -> _FloatArray:
        """(a, b, c) in metres."""

@final
class ContactResult:
    """Minkowski contact features of a pair (a, b), world frame, normal from a towards b."""

    @property
    def status(self) -> str:
        """'overlap', 'touching' or 'separated'."""
    @property
    def solver(self) -> str:
        """'exact', 'converged', 'fallback_after_max_iterations' or 'fallback_after_degenerate'."""
    @property
    def depth(self) -> float:
        """Minkowski overlap (m), zero unless overlapping."""
    @property
    def distance(self) -> float:
        """Gap (m), zero unless separated."""
    @property
    def normal(self) -> _FloatArray:
        """Unit normal from a towards b, shape (3,)."""
    @property
    def point_a(self) -> _FloatArray:
        """Contact point on a's surface (m)."""
    @property
    def point_b(self) -> _FloatArray:
        """Contact point on b's surface (m)."""
    @property
    def point(self) -> _FloatArray:
        """Midpoint of point_a and point_b (m)."""

def contact(
    a: Shape, b: Shape, pose_a: Optional[_Pose] = None, pose_b: Optional[_Pose] = None
) -> ContactResult:
    """The contact between a at pose_a and b at pose_b (None: identity), as `polydem contact` answers it."""

def contact_batch(
    a: Union[Shape, Sequence[Shape]],
    b: Union[Shape, Sequence[Shape]],
    pose_a: Optional[Tuple[_ArrayLike, _ArrayLike]] = None,
    pose_b: Optional[Tuple[_ArrayLike, _ArrayLike]] = None,
) -> dict[str, np.ndarray]:
    """The contacts of n pairs as arrays (status, solver, depth, distance: (n,); normal, point_a, point_b,
    point: (n, 3)). a, b: one Shape for every pair or n Shapes; poses: None or (positions (n, 3),
    quaternions (n, 4) as w, x, y, z). Computed in parallel with the GIL released; equal to contact()."""

@final
class Scene:
    """A scene read and validated by the engine; start Simulations from it."""

    @staticmethod
    def from_toml(path: _StrPath) -> Scene:
        """Reads a scene file; SceneError with the engine's message (file, line, field) on failure."""
    @staticmethod
    def from_string(text: str, path: _StrPath = ...) -> Scene:
        """Builds a scene from TOML text; `path` (default "<string>") names it in error messages."""
    @staticmethod
    def from_dict(scene: Mapping[str, Any], path: _StrPath = ...) -> Scene:
        """Builds a scene from a dict shaped like the scene file, read as the TOML text scene_to_toml(scene)
        gives (the same validation and messages as a file); `path` (default "<dict>") names it in errors."""
    @property
    def num_bodies(self) -> int: ...
    @property
    def dt(self) -> float:
        """Time step (s)."""
    @property
    def end_time(self) -> float:
        """End time of the scene (s)."""

@final
class Simulation:
    """A running simulation. Every array returned is a copy: the state belongs to the engine and changes
    at the next step."""

    def __new__(cls, scene: Scene) -> Simulation: ...
    @staticmethod
    def from_toml(path: _StrPath) -> Simulation: ...
    def step(self, n: int = 1) -> None:
        """Advances n steps in the engine with the GIL released; StepError if a step fails. Ctrl-C
        (KeyboardInterrupt) stops it within about 0.1 s (64 steps at most past that) at a step boundary:
        `step_index` says where, and the simulation goes on from there as if never interrupted."""
    def run(
        self,
        until: Optional[float] = None,
        every: Optional[float] = None,
        callback: Optional[Callable[[Simulation], object]] = None,
        *,
        progress: Optional[Callable[[int, int], object]] = None,
        out: Optional[_StrPath] = None,
        vtk_interval: Optional[float] = None,
        contacts_interval: Optional[float] = None,
        checkpoint_interval: Optional[float] = None,
        max_steps: Optional[int] = None,
    ) -> None:
        """Runs to `until` (s; default the scene's end time), calling callback(sim) every `every` seconds
        (whole steps, at least one) and at the end, and progress(step, last_step) about every hundredth of
        the run; with `out`, writes the outputs of `polydem run --out` there (CSV series; VTK frames,
        contact network, checkpoints at the given intervals in s). GIL released except for the callbacks.
        Ctrl-C (KeyboardInterrupt) stops it within about 0.1 s (64 steps at most past that) at a step
        boundary, outputs flushed; the simulation goes on from there as if never interrupted."""
    def contacts(self) -> Dict[str, npt.NDArray[Any]]:
        """The active contacts: `wall` (bool), `a`, `b` (int64 indices; a wall's index for a wall contact),
        `point`, `normal` (n, 3), `depth` (n,), `force` on b (n, 3); world frame, copies."""
    def walls(self) -> Dict[str, Any]:
        """The walls: `names`, and (k, 3) arrays `point`, `normal`, `velocity`, `force` (copies)."""
    def set_wall_velocity(self, name: str, velocity: _ArrayLike) -> None:
        """Sets the prescribed velocity (m/s) of the wall `name`; KeyError if there is none."""
    @property
    def time(self) -> float:
        """Simulated time (s)."""
    @property
    def step_index(self) -> int:
        """Steps done since the start of the scene."""
    @property
    def dt(self) -> float:
        """Time step (s)."""
    @property
    def num_bodies(self) -> int: ...
    @property
    def end_time(self) -> float:
        """End time of the scene (s); step() may go past it."""
    @property
    def end_step(self) -> int:
        """The step index at the scene's end time (the steps `polydem run` does)."""
    @property
    def names(self) -> Sequence[str]: ...
    def positions(self) -> _FloatArray:
        """Centre-of-mass positions (m), shape (N, 3), a copy."""
    def velocities(self) -> _FloatArray:
        """Velocities (m/s), shape (N, 3), a copy."""
    def orientations(self) -> _FloatArray:
        """Unit quaternions (w, x, y, z) of the bodies' input frames, shape (N, 4), a copy."""
    def angular_velocities(self) -> _FloatArray:
        """World-frame angular velocities (rad/s), shape (N, 3), a copy."""
    def forces(self) -> _FloatArray:
        """Contact forces (N, world frame, gravity excluded) of the last evaluation, (N, 3), a copy;
        RuntimeError before the first step."""
    def torques(self) -> _FloatArray:
        """Contact torques about the centres of mass (N·m), (N, 3), a copy; RuntimeError before the first
        step."""
    def energy(self) -> dict[str, float]:
        """The energy ledger (J) and its time (s)."""
    def save(self, path: _StrPath) -> int:
        """Writes a checkpoint; returns the bytes written."""
    @staticmethod
    def load(path: _StrPath) -> Simulation:
        """Restores a checkpoint (from save or polydem run); continues bit for bit."""
    def to_bytes(self) -> bytes:
        """The checkpoint bytes of the state."""
    @classmethod
    def from_bytes(cls, data: bytes) -> Simulation:
        """Restores checkpoint bytes."""

def scene_to_toml(scene: Mapping[str, Any]) -> str:
    """The TOML text of a scene given as a dict shaped like the scene file (None values left out);
    TypeError naming the key of a value TOML cannot hold."""

def rockfill(
    out: _StrPath,
    config: Optional[Union[str, _StrPath]] = None,
    *,
    size_mm: Optional[float] = None,
    seed: Optional[int] = None,
    bed: Optional[_StrPath] = None,
    progress: Optional[Callable[[str, str], object]] = None,
    max_rocks: Optional[int] = None,
    max_steps: Optional[int] = None,
) -> Dict[str, Any]:
    """The paper's rockfill experiment (`polydem rockfill`) with its outputs in `out`: "quick", "paper" or an
    experiment file; returns the penetration's figures and `monitors`, a dict of per-step arrays. Ctrl-C
    (KeyboardInterrupt) or an exception from `progress` stops the packing or the penetration between two
    steps and is raised; the outputs of a finished run are then not written."""

def contact_oracle(a: Shape, b: Shape, pose_a: Optional[_Pose] = None, pose_b: Optional[_Pose] = None) -> ContactResult:
    """The separating-axis oracle's exact answer for two ConvexPolyhedron shapes (slow; the reference the
    engine's GJK/EPA is verified against); ValueError for other shapes."""
