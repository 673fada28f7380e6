"""polydem: a convex-polyhedral discrete element engine, from Python.

Shapes and contact queries::

    import numpy as np, polydem
    cube = polydem.ConvexPolyhedron.from_points(np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)]))
    r = polydem.contact(cube, cube, pose_b=([1.5, 0, 0], [1, 0, 0, 0]))
    r.status, r.distance, r.normal          # 'separated', 0.5, [1, 0, 0]

Simulations from scene files::

    sim = polydem.Simulation(polydem.Scene.from_toml("scenes/two_polyhedra_elastic.toml"))
    sim.step(100)                           # in Rust, with the GIL released
    sim.positions(), sim.energy()           # numpy copies of the state, the energy ledger

Scenes built in Python, run with the outputs of ``polydem run``::

    scene = polydem.Scene.from_dict({"simulation": {...}, "material": [...], "interaction": [...],
                                     "shape": [...], "body": polydem.bodies("grain", count=n, shape="ball",
                                     material="steel", position=xyz), "wall": [...]})
    polydem.Simulation(scene).run(out="out/run", vtk_interval=0.01, progress=lambda k, n: print(k, n))

Every array the package returns is a copy: the state belongs to the engine and changes at the next step.
Lengths in metres, times in seconds, SI units throughout. Poses are ``(position[3], quaternion[4])`` with
the quaternion as (w, x, y, z).
"""

from ._polydem import (
    CheckpointError,
    ContactResult,
    ConvexPolyhedron,
    Ellipsoid,
    Scene,
    SceneError,
    Shape,
    Simulation,
    Sphere,
    StepError,
    __version__,
    contact,
    contact_batch,
    contact_oracle,
    rockfill,
    scene_to_toml,
)
from .scene_builder import bodies
from .validation import find_checkout, validate

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
