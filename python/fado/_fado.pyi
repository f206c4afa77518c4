"""Type stubs of the native module ``fado._fado`` (built from ``crates/fado-py``).

Import these names from ``fado``. ``tests/python/test_stubs.py`` runs ``mypy.stubtest`` on
this file, so it cannot drift from the module.
"""

import inspect
import os
from collections.abc import Mapping
from typing import Any, ClassVar, Final, Literal, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "Machine",
    "machine_presets",
    "EstimatorConfig",
    "Estimator",
    "estimate",
    "EstimateResult",
    "StepResult",
    "MODE_LIMITER",
    "MODE_DISTURBANCE_FEEDBACK",
    "FadoError",
    "ConfigError",
    "InputError",
    "SimulationError",
    "__version__",
    "OUTPUT_NAMES",
    "TRACE_COLUMNS",
    "SWEEP_PARAMETERS",
    "simulate",
    "SimResult",
    "scenarios",
    "estimators",
    "describe_scenario",
    "default_config",
    "compare",
    "sweep",
    "sweep_point",
    "commission",
    "CommissionResult",
    "COMMISSION_TRACE_COLUMNS",
    "COMMISSION_PHASES",
]

__version__: Final[str]
OUTPUT_NAMES: Final[list[str]]
TRACE_COLUMNS: Final[list[str]]
COMMISSION_TRACE_COLUMNS: Final[list[str]]
COMMISSION_PHASES: Final[list[str]]
SWEEP_PARAMETERS: Final[dict[str, str]]
MODE_LIMITER: Final[int]
MODE_DISTURBANCE_FEEDBACK: Final[int]

_FloatArray = npt.NDArray[np.float64] | npt.NDArray[np.float32]
_DType = Literal["float64", "float32"]
_MachineLike = Machine | str | dict[str, Any]
_FluxMapLike = (
    str
    | os.PathLike[str]
    | tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike, npt.ArrayLike]
)
_ConfigLike = EstimatorConfig | dict[str, Any] | None

class FadoError(Exception):
    """Base class of every error fado raises on purpose."""

class ConfigError(FadoError, ValueError):
    """A configuration field is invalid; ``.field`` names it.

    Raised by :func:`fado.simulate` for a TOML key, it also has ``.line`` and ``.column``
    (1-based) of the key's value in the TOML text, or ``None`` when the text does not set it.
    """

    field: str
    line: int | None
    column: int | None

class InputError(FadoError, ValueError):
    """An input array or argument is unusable; ``.argument`` names it."""

    argument: str

class SimulationError(FadoError):
    """A simulation could not be run or failed."""

@final
class Machine:
    """The motor's parameters and ratings (``fado_core::MachineModel``), validated."""

    fields: ClassVar[tuple[str, ...]]
    __signature__: ClassVar[inspect.Signature]
    def __new__(
        cls,
        *,
        rs: float,
        ld: float,
        lq: float,
        flux_linkage: float,
        pole_pairs: int,
        rated_current: float,
        rated_speed_rpm: float,
        rated_torque: float,
        dc_voltage: float | None = None,
        inertia: float | None = None,
        viscous_friction: float | None = None,
        flux_map: _FluxMapLike | None = None,
    ) -> Machine: ...
    def replace(
        self,
        *,
        rs: float | None = None,
        ld: float | None = None,
        lq: float | None = None,
        flux_linkage: float | None = None,
        pole_pairs: int | None = None,
        inertia: float | None = None,
        rated_current: float | None = None,
        rated_speed_rpm: float | None = None,
        rated_torque: float | None = None,
        dc_voltage: float | None = None,
        viscous_friction: float | None = None,
        flux_map: _FluxMapLike | None = None,
    ) -> Machine: ...
    @staticmethod
    def from_datasheet(**fields: Any) -> Machine:
        """A machine from its datasheet's values: any field, or ``rs_line_to_line``, ``l_line_to_line``, ``ke_vll_rms_per_krpm``, ``ke_vll_peak_per_krpm``, ``kt_nm_per_arms``, ``rated_current_arms``, ``kv_rpm_per_volt``, ``inertia_kg_cm2`` in their place."""
    @staticmethod
    def paper() -> Machine:
        """The paper's motor."""
    @staticmethod
    def preset(name: str) -> Machine:
        """A motor preset of the repository's ``motors/`` folder."""
    def to_dict(self) -> dict[str, Any]: ...
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, Any]]: ...
    @property
    def flux_map(
        self,
    ) -> (
        str
        | tuple[
            npt.NDArray[np.float64],
            npt.NDArray[np.float64],
            npt.NDArray[np.float64],
            npt.NDArray[np.float64],
        ]
        | None
    ):
        """The plant's flux map: None, the CSV path, or the node arrays of a map given as arrays."""
    def __eq__(self, value: object, /) -> bool: ...
    def __ne__(self, value: object, /) -> bool: ...
    @property
    def salient(self) -> bool:
        """Ld and Lq differ by more than 2 %."""
    @property
    def rs(self) -> float:
        """Stator resistance Rs in Ω (per phase)."""
    @property
    def ld(self) -> float:
        """d-axis inductance Ld in H."""
    @property
    def lq(self) -> float:
        """q-axis inductance Lq in H."""
    @property
    def flux_linkage(self) -> float:
        """Magnet flux linkage λf in Wb (peak, per phase)."""
    @property
    def pole_pairs(self) -> int:
        """Pole pairs p."""
    @property
    def inertia(self) -> float:
        """Shaft inertia J in kg·m²."""
    @property
    def viscous_friction(self) -> float:
        """Viscous friction B in N·m·s/rad."""
    @property
    def rated_current(self) -> float:
        """Rated current in A peak."""
    @property
    def rated_speed_rpm(self) -> float:
        """Rated speed in r/min (mechanical)."""
    @property
    def rated_torque(self) -> float:
        """Rated torque in N·m."""
    @property
    def dc_voltage(self) -> float:
        """Nominal DC-link voltage in V."""

def _unexpected_keyword(function: str, key: str, accepted: list[str]) -> str:
    """The message of the TypeError for a keyword that `function` does not take."""

def machine_presets() -> list[str]:
    """The names of the motor presets."""

@final
class EstimatorConfig:
    """Tuning of the sensorless estimator, one dict per block it tunes (`lock`, `tracker`,
    ...); omitted fields take the Rust defaults."""

    fields: ClassVar[tuple[str, ...]]
    __signature__: ClassVar[inspect.Signature]
    def __new__(
        cls,
        *,
        integrator: Mapping[str, float | str | bool] | None = None,
        disturbance_feedback: Mapping[str, float | str | bool] | None = None,
        limiter: Mapping[str, float | str | bool] | None = None,
        mode: Mapping[str, float | str | bool] | None = None,
        tracker: Mapping[str, float | str | bool] | None = None,
        observer: Mapping[str, float | str | bool] | None = None,
        rs_adaptation: Mapping[str, float | str | bool] | None = None,
        flux_linkage_adaptation: Mapping[str, float | str | bool] | None = None,
        offset_adaptation: Mapping[str, float | str | bool] | None = None,
        plausibility: Mapping[str, float | str | bool] | None = None,
        lock: Mapping[str, float | str | bool] | None = None,
    ) -> EstimatorConfig: ...
    def replace(
        self,
        /,
        *,
        integrator: Mapping[str, float | str | bool] | None = None,
        disturbance_feedback: Mapping[str, float | str | bool] | None = None,
        limiter: Mapping[str, float | str | bool] | None = None,
        mode: Mapping[str, float | str | bool] | None = None,
        tracker: Mapping[str, float | str | bool] | None = None,
        observer: Mapping[str, float | str | bool] | None = None,
        rs_adaptation: Mapping[str, float | str | bool] | None = None,
        flux_linkage_adaptation: Mapping[str, float | str | bool] | None = None,
        offset_adaptation: Mapping[str, float | str | bool] | None = None,
        plausibility: Mapping[str, float | str | bool] | None = None,
        lock: Mapping[str, float | str | bool] | None = None,
    ) -> EstimatorConfig: ...
    def to_dict(self) -> dict[str, dict[str, float | str | bool]]: ...
    def paper_path(self) -> EstimatorConfig:
        """A copy on the paper's path: every addition of fado's that can be off, off (fixed
        R̂s, observer on λ1 at T2S-1's ω̂, no re-centring, abrupt k_df, gains every sample)."""
    def __getnewargs_ex__(
        self,
    ) -> tuple[tuple[()], dict[str, dict[str, float | str | bool]]]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __ne__(self, value: object, /) -> bool: ...
    @property
    def integrator(self) -> dict[str, float | str | bool]:
        """Tuning of the flux integrator (eq. (3)) (the fields of `IntegratorTuning`)."""
    @property
    def disturbance_feedback(self) -> dict[str, float | str | bool]:
        """Tuning of the disturbance feedback k_df (Fig. 3) (the fields of `DisturbanceFeedbackTuning`)."""
    @property
    def limiter(self) -> dict[str, float | str | bool]:
        """Tuning of the flux limiter (Fig. 6) (the fields of `LimiterTuning`)."""
    @property
    def mode(self) -> dict[str, float | str | bool]:
        """Tuning of the selection between limiter and k_df (Fig. 3) (the fields of `ModeTuning`)."""
    @property
    def tracker(self) -> dict[str, float | str | bool]:
        """Tuning of the speed trackers T2S-1 and T2S-2 (the fields of `TrackerTuning`)."""
    @property
    def observer(self) -> dict[str, float | str | bool]:
        """Tuning of the disturbance observer (Fig. 5) (the fields of `ObserverTuning`)."""
    @property
    def rs_adaptation(self) -> dict[str, float | str | bool]:
        """Tuning of the online R̂s law (the fields of `RsAdaptationTuning`)."""
    @property
    def flux_linkage_adaptation(self) -> dict[str, float | str | bool]:
        """Tuning of the λ̂f law (the fields of `FluxLinkageAdaptationTuning`)."""
    @property
    def offset_adaptation(self) -> dict[str, float | str | bool]:
        """Tuning of the integrand-offset law (the fields of `OffsetAdaptationTuning`)."""
    @property
    def plausibility(self) -> dict[str, float | str | bool]:
        """Tuning of the sample bounds (the fields of `PlausibilityTuning`)."""
    @property
    def lock(self) -> dict[str, float | str | bool]:
        """Tuning of the loss-of-lock detector (the fields of `LockTuning`)."""

@final
class StepResult:
    """One sample of the estimator's outputs and diagnostics (Fig. 5)."""

    def to_dict(self) -> dict[str, float | int | bool]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __ne__(self, value: object, /) -> bool: ...
    @property
    def theta(self) -> float: ...
    @property
    def omega(self) -> float: ...
    @property
    def omega_control(self) -> float: ...
    @property
    def theta_direct(self) -> float: ...
    @property
    def lambda1_alpha(self) -> float: ...
    @property
    def lambda1_beta(self) -> float: ...
    @property
    def disturbance_alpha(self) -> float: ...
    @property
    def disturbance_beta(self) -> float: ...
    @property
    def lambda2_alpha(self) -> float: ...
    @property
    def lambda2_beta(self) -> float: ...
    @property
    def lambda_r_alpha(self) -> float: ...
    @property
    def lambda_r_beta(self) -> float: ...
    @property
    def rs_hat(self) -> float: ...
    @property
    def flux_linkage_hat(self) -> float: ...
    @property
    def mode(self) -> int: ...
    @property
    def lock(self) -> int: ...
    @property
    def flag_limit(self) -> bool: ...
    @property
    def limiter_clamping(self) -> bool: ...
    @property
    def tracker_hold(self) -> bool: ...
    @property
    def input_fault(self) -> bool: ...

@final
class EstimateResult:
    """The estimator's outputs over a recording, one numpy array per field."""

    def to_dict(self) -> dict[str, npt.NDArray[Any]]: ...
    def keys(self) -> list[str]: ...
    def to_pandas(self) -> Any: ...
    def __getitem__(self, name: str, /) -> npt.NDArray[Any]: ...
    def __len__(self) -> int: ...
    @property
    def time(self) -> npt.NDArray[np.float64]: ...
    @property
    def ts(self) -> float: ...
    @property
    def dtype(self) -> _DType: ...
    @property
    def theta(self) -> _FloatArray: ...
    @property
    def omega(self) -> _FloatArray: ...
    @property
    def omega_control(self) -> _FloatArray: ...
    @property
    def theta_direct(self) -> _FloatArray: ...
    @property
    def lambda1_alpha(self) -> _FloatArray: ...
    @property
    def lambda1_beta(self) -> _FloatArray: ...
    @property
    def disturbance_alpha(self) -> _FloatArray: ...
    @property
    def disturbance_beta(self) -> _FloatArray: ...
    @property
    def lambda2_alpha(self) -> _FloatArray: ...
    @property
    def lambda2_beta(self) -> _FloatArray: ...
    @property
    def lambda_r_alpha(self) -> _FloatArray: ...
    @property
    def lambda_r_beta(self) -> _FloatArray: ...
    @property
    def rs_hat(self) -> _FloatArray: ...
    @property
    def flux_linkage_hat(self) -> _FloatArray: ...
    @property
    def mode(self) -> npt.NDArray[np.int8]: ...
    @property
    def lock(self) -> npt.NDArray[np.int8]: ...
    @property
    def flag_limit(self) -> npt.NDArray[np.bool_]: ...
    @property
    def limiter_clamping(self) -> npt.NDArray[np.bool_]: ...
    @property
    def tracker_hold(self) -> npt.NDArray[np.bool_]: ...
    @property
    def input_fault(self) -> npt.NDArray[np.bool_]: ...

@final
class Estimator:
    """The sensorless estimator of Fig. 5, stepped sample by sample or chunk by chunk."""

    def __new__(
        cls,
        machine: _MachineLike,
        config: _ConfigLike = None,
        *,
        ts: float = 0.0001,
        theta0: float = 0.0,
        dtype: npt.DTypeLike = "float64",
    ) -> Estimator: ...
    @property
    def config(self) -> EstimatorConfig: ...
    @property
    def machine(self) -> Machine: ...
    @property
    def ts(self) -> float: ...
    @property
    def theta0(self) -> float: ...
    @property
    def dtype(self) -> _DType: ...
    @property
    def last(self) -> StepResult: ...
    @property
    def rejected_samples(self) -> int: ...
    def step(self, v_alpha: float, v_beta: float, i_alpha: float, i_beta: float) -> StepResult: ...
    def run(
        self, v_alpha: _FloatArray, v_beta: _FloatArray, i_alpha: _FloatArray, i_beta: _FloatArray
    ) -> EstimateResult: ...
    def reset(self) -> None: ...
    def align(self, theta0: float, i_alpha: float = 0.0, i_beta: float = 0.0) -> None: ...
    def set_disturbance_feedback_enabled(self, enabled: bool) -> None: ...
    def set_rs_hat(self, rs_hat: float) -> None: ...
    def copy(self) -> Estimator: ...

def estimate(
    v_alpha: _FloatArray,
    v_beta: _FloatArray,
    i_alpha: _FloatArray,
    i_beta: _FloatArray,
    *,
    machine: _MachineLike,
    ts: float = 0.0001,
    config: _ConfigLike = None,
    theta0: float | None = None,
    dtype: npt.DTypeLike = "float64",
) -> EstimateResult:
    """Run the estimator over a whole recording in Rust (GIL released)."""

@final
class SimResult:
    """A finished simulation: ``metrics.json`` and ``traces.csv`` of ``fado-sim run``."""

    @property
    def scenario(self) -> str: ...
    @property
    def passed(self) -> bool: ...
    @property
    def averaged(self) -> bool: ...
    @property
    def config_toml(self) -> str: ...
    @property
    def estimator_config(self) -> EstimatorConfig: ...
    @property
    def machine(self) -> Machine: ...
    @property
    def ts(self) -> float: ...
    @property
    def theta0(self) -> float: ...
    @property
    def metrics(self) -> dict[str, Any]: ...
    @property
    def checks(self) -> list[dict[str, Any]]: ...
    @property
    def traces(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def time(self) -> npt.NDArray[np.float64]: ...
    def to_pandas(self) -> Any: ...
    def __getitem__(self, name: str, /) -> npt.NDArray[np.float64]: ...
    def __len__(self) -> int: ...

def simulate(
    scenario: str = "fig11",
    config_toml: str | None = None,
    averaged: bool = False,
    *,
    progress: bool = False,
    motor: _MachineLike | None = None,
) -> SimResult:
    """Run a scenario (the paper's Fig. 8–12, or one scaled by the motor's ratings) on the simulated drive (GIL released)."""

def scenarios() -> list[str]:
    """The scenario names."""

def describe_scenario(scenario: str) -> dict[str, str]:
    """Name, title, profile and pass criterion of a scenario."""

def default_config(
    scenario: str = "fig11", averaged: bool = False, *, motor: _MachineLike | None = None
) -> str:
    """The scenario's configuration as TOML (``fado-sim run --dump-config``)."""

def estimators() -> list[str]:
    """The estimator names ``compare`` runs by default, in its order."""

def compare(
    scenarios: list[str] | None = None,
    estimators: list[str] | None = None,
    averaged: bool = False,
    *,
    config: str | None = None,
    traces: bool = False,
    threads: int = 2,
) -> list[dict[str, Any]]:
    """Every estimator in every scenario on the same plant and seed (GIL released)."""

def sweep(
    scenario: str,
    axes: list[str],
    points: list[list[Any]],
    *,
    config: str | None = None,
    averaged: bool = False,
    threads: int = 0,
    out: str | os.PathLike[str] | None = None,
    fresh: bool = False,
    progress: bool = False,
) -> list[dict[str, Any]]:
    """One scenario run per point on a rayon pool (GIL released); one row dict per point."""

def sweep_point(
    scenario: str,
    axes: list[str],
    values: list[Any],
    *,
    config: str | None = None,
    averaged: bool = False,
    index: int = 0,
) -> dict[str, Any]:
    """One point of a sweep (GIL released): its row dict."""

@final
class CommissionResult:
    """A commissioning run on the simulated plant: ``fado-sim commission``'s output."""

    @property
    def passed(self) -> bool: ...
    @property
    def status(self) -> str: ...
    @property
    def machine(self) -> Machine | None: ...
    @property
    def inverter_voltage(self) -> float | None: ...
    @property
    def threshold_voltage(self) -> float | None: ...
    @property
    def saliency(self) -> float | None: ...
    @property
    def simulated_seconds(self) -> float: ...
    @property
    def wall_seconds(self) -> float: ...
    @property
    def max_current(self) -> float: ...
    @property
    def max_current_reference(self) -> float: ...
    @property
    def current_limit(self) -> float: ...
    @property
    def rotor_motion_inductance(self) -> float: ...
    @property
    def rotor_motion_magnetics(self) -> float: ...
    @property
    def saturation_detected(self) -> bool | None: ...
    @property
    def saturation_verdict(self) -> str | None: ...
    @property
    def config_toml(self) -> str: ...
    @property
    def identified_toml(self) -> str | None: ...
    @property
    def truth(self) -> dict[str, float]: ...
    @property
    def parameters(self) -> list[dict[str, Any]]: ...
    @property
    def errors(self) -> dict[str, float]: ...
    @property
    def confidence(self) -> dict[str, float]: ...
    @property
    def traces(self) -> dict[str, npt.NDArray[np.float64]]: ...
    def __getitem__(self, name: str, /) -> npt.NDArray[np.float64]: ...
    def __len__(self) -> int: ...

def commission(
    motor: _MachineLike,
    *,
    nameplate: _MachineLike | None = None,
    config_toml: str | None = None,
    seed: int = 1,
    averaged: bool = False,
    theta0: float = 1.0,
    decimation: int = 10,
    progress: bool = False,
) -> CommissionResult:
    """Run the commissioning procedure on the simulated plant (GIL released)."""
