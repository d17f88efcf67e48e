"""Type stubs of the Python module `impactdeck` (python/impactdeck_module.cpp; docs/python.md).

Hand-written: tests/test_python.py checks that every public name of the module is here and that
every name here exists in the module."""
import os
from typing import Any, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_PathLike = Union[str, "os.PathLike[str]"]
# An override's value, written as TOML: bool, int, float, str, lists, tuples, dicts, numpy arrays and scalars.
_OverrideValue = Any
_Overrides = Optional[Mapping[str, _OverrideValue]]
_Vector3 = Union[Sequence[float], npt.NDArray[np.float64]]


class Error(Exception):
    """Every error of impactdeck; `exit_code` is the command's exit code (docs/cli.md)."""
    exit_code: int


class UsageError(Error):
    """A call made wrongly (the command's exit code 2)."""


class InputError(Error):
    """Bad input: a file, scene key or value (exit code 3); the message names file, place and reason."""


class CheckFailed(Error):
    """A physics self-check failed (exit code 4); `document` holds the complete document when there is one."""


class InternalError(Error):
    """A defect of impactdeck (exit code 1)."""


class Part:
    """A part file loaded as a shape: mass properties and surface queries (SI, metres)."""

    @property
    def file(self) -> str: ...
    @property
    def format(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def volume_m3(self) -> float: ...
    @property
    def area_m2(self) -> float: ...
    @property
    def center_of_mass_m(self) -> npt.NDArray[np.float64]: ...
    @property
    def inertia_per_density_m5(self) -> npt.NDArray[np.float64]: ...
    @property
    def size_m(self) -> float: ...
    def closest_point(self, point_m: _Vector3) -> dict[str, Any]: ...
    def curvature(self, point_m: _Vector3) -> dict[str, Any]: ...
    def sample_surface(self, count: int, seed: int = 1) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...


def run(scene_path: _PathLike, out: Optional[_PathLike] = None, overrides: _Overrides = None) -> dict[str, Any]: ...


def inspect(path: _PathLike, length_unit: str, density_kg_m3: Optional[float] = None,
            at: Optional[Sequence[Union[str, _Vector3]]] = None) -> dict[str, Any]: ...


def solve_impact(*, mass1_kg: float, mass2_kg: float, inertia1_kg_m2: Any, inertia2_kg_m2: Any,
                 lever_arm1_m: _Vector3, lever_arm2_m: _Vector3, normal: _Vector3, velocity1_m_s: _Vector3,
                 velocity2_m_s: _Vector3, angular_velocity1_rad_s: Optional[_Vector3] = None,
                 angular_velocity2_rad_s: Optional[_Vector3] = None, radius_m: Optional[float] = None,
                 curvatures1_per_m: Optional[Tuple[float, float]] = None,
                 curvatures2_per_m: Optional[Tuple[float, float]] = None, directions1: Optional[_Vector3] = None,
                 directions2: Optional[_Vector3] = None, effective_modulus_Pa: float,
                 restitution: Union[float, str] = 1.0, samples: int = 201) -> dict[str, Any]: ...


def load_part(path: _PathLike, length_unit: str, repair: bool = False, accept_approximate: bool = False) -> Part: ...


def sweep(scene_path: _PathLike, impact: str = "", cloud: str = "auto", count: int = 2000, seed: int = 1,
          grid_steps: int = 8, threads: int = 0, overrides: _Overrides = None) -> dict[str, Any]: ...


def fem_check(deck_dir: _PathLike, *, ccx: str = "ccx", run: bool = True, linear_tolerance: float = 0.0,
              angular_tolerance: float = 0.0, threads: int = 0, solver_timeout_s: float = 0.0) -> dict[str, Any]: ...


def compare_contact(scene_path: _PathLike, out: Optional[_PathLike] = None, overrides: _Overrides = None, *,
                    impact: str = "", threshold: float = 0.03, refine: int = 0, hybrid: bool = True,
                    solver_timeout_s: float = 0.0) -> dict[str, Any]: ...


def campaign_plan(campaign_file: _PathLike, out: _PathLike) -> dict[str, Any]: ...


def campaign_run(dir: _PathLike, *, jobs: int = 1, threads: int = 1,
                 executable: Optional[_PathLike] = None) -> dict[str, Any]: ...


def campaign_collect(dir: _PathLike) -> dict[str, Any]: ...
