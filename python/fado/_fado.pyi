"""Type stubs of the native module ``fado._fado`` (built from ``crates/fado-py``).

Import these names from ``fado``. ``tests/python/test_stubs.py`` runs ``mypy.stubtest`` on
this file, so it cannot drift from the module.
"""

import inspect
import os
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
        dc_voltage: float,
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

def machine_presets() -> list[str]:
    """The names of the motor presets."""

@final
class EstimatorConfig:
    """Tuning of the sensorless estimator; omitted fields take the Rust defaults."""

    fields: ClassVar[tuple[str, ...]]
    __signature__: ClassVar[inspect.Signature]
    def __new__(
        cls,
        *,
        k_df: float | None = None,
        k_df_ramp_time: float | None = None,
        k_af: float | None = None,
        limiter_radius_ratio: float | None = None,
        mode_threshold_ratio: float | None = None,
        mode_hysteresis_ratio: float | None = None,
        t2s1_bandwidth_hz: float | None = None,
        t2s2_bandwidth_hz: float | None = None,
        tracker_damping: float | None = None,
        bandwidth_definition: str | None = None,
        tracker_hold_ratio: float | None = None,
        tracker_load_pole_ratio: float | None = None,
        average_current: bool | None = None,
        observer_on_rotor_flux: bool | None = None,
        observer_lag_compensation: bool | None = None,
        observer_gain_period: float | None = None,
        rs_adaptation: bool | None = None,
        rs_adaptation_rate: float | None = None,
        rs_adaptation_excitation_floor: float | None = None,
        rs_adaptation_min_ratio: float | None = None,
        rs_adaptation_max_ratio: float | None = None,
        flux_linkage_adaptation_rate: float | None = None,
        offset_adaptation_rate: float | None = None,
        standstill_angle_rate: float | None = None,
        limiter_recentring: bool | None = None,
        plausible_current_ratio: float | None = None,
        plausible_voltage_ratio: float | None = None,
        plausible_current_step_ratio: float | None = None,
        lock_flux_low_ratio: float | None = None,
        lock_flux_low_fast_ratio: float | None = None,
        lock_flux_high_ratio: float | None = None,
        lock_innovation_limit: float | None = None,
        lock_detection_time: float | None = None,
        lock_heal_time: float | None = None,
        lock_limiter_clamping: bool | None = None,
        lock_handover_count: float | None = None,
        lock_handover_time: float | None = None,
    ) -> EstimatorConfig: ...
    def replace(
        self,
        *,
        k_df: float | None = None,
        k_df_ramp_time: float | None = None,
        k_af: float | None = None,
        limiter_radius_ratio: float | None = None,
        mode_threshold_ratio: float | None = None,
        mode_hysteresis_ratio: float | None = None,
        t2s1_bandwidth_hz: float | None = None,
        t2s2_bandwidth_hz: float | None = None,
        tracker_damping: float | None = None,
        bandwidth_definition: str | None = None,
        tracker_hold_ratio: float | None = None,
        tracker_load_pole_ratio: float | None = None,
        average_current: bool | None = None,
        observer_on_rotor_flux: bool | None = None,
        observer_lag_compensation: bool | None = None,
        observer_gain_period: float | None = None,
        rs_adaptation: bool | None = None,
        rs_adaptation_rate: float | None = None,
        rs_adaptation_excitation_floor: float | None = None,
        rs_adaptation_min_ratio: float | None = None,
        rs_adaptation_max_ratio: float | None = None,
        flux_linkage_adaptation_rate: float | None = None,
        offset_adaptation_rate: float | None = None,
        standstill_angle_rate: float | None = None,
        limiter_recentring: bool | None = None,
        plausible_current_ratio: float | None = None,
        plausible_voltage_ratio: float | None = None,
        plausible_current_step_ratio: float | None = None,
        lock_flux_low_ratio: float | None = None,
        lock_flux_low_fast_ratio: float | None = None,
        lock_flux_high_ratio: float | None = None,
        lock_innovation_limit: float | None = None,
        lock_detection_time: float | None = None,
        lock_heal_time: float | None = None,
        lock_limiter_clamping: bool | None = None,
        lock_handover_count: float | None = None,
        lock_handover_time: float | None = None,
    ) -> EstimatorConfig: ...
    def to_dict(self) -> dict[str, float | str | bool]: ...
    def paper_path(self) -> EstimatorConfig:
        """A copy on the paper's path: every addition of fado's that can be off, off (fixed
        R̂s, observer on λ1 at T2S-1's ω̂, no re-centring, abrupt k_df, gains every sample)."""
    def __getnewargs_ex__(self) -> tuple[tuple[()], dict[str, float | str | bool]]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __ne__(self, value: object, /) -> bool: ...
    @property
    def k_df(self) -> float:
        """Disturbance feedback gain k_df in 1/s (Fig. 3)."""
    @property
    def k_df_ramp_time(self) -> float:
        """Ramp time of k_df on activation in s."""
    @property
    def k_af(self) -> float:
        """Limiter gain k_af in 1/s (Fig. 6)."""
    @property
    def limiter_radius_ratio(self) -> float:
        """Limiter radius as a multiple of λ̂f."""
    @property
    def mode_threshold_ratio(self) -> float:
        """Speed threshold between limiter and k_df feedback as a fraction of the rated electrical frequency."""
    @property
    def mode_hysteresis_ratio(self) -> float:
        """Hysteresis half-band of the threshold as a fraction of the rated electrical frequency."""
    @property
    def t2s1_bandwidth_hz(self) -> float:
        """Bandwidth of T2S-1 in Hz."""
    @property
    def t2s2_bandwidth_hz(self) -> float:
        """Bandwidth of T2S-2 in Hz."""
    @property
    def tracker_damping(self) -> float:
        """Damping ratio of both trackers."""
    @property
    def bandwidth_definition(self) -> str:
        """'minus3_db' or 'natural_frequency'."""
    @property
    def tracker_hold_ratio(self) -> float:
        """Trackers coast while |λ̂r| is below this fraction of λ̂f."""
    @property
    def tracker_load_pole_ratio(self) -> float:
        """The trackers' load-acceleration pole as a ratio of ωn (0: type-2 trackers)."""
    @property
    def average_current(self) -> bool:
        """Average the current over the interval for the resistive drop."""
    @property
    def observer_on_rotor_flux(self) -> bool:
        """Observer fed with λ1 − L̂q·i (fado's improvement) instead of λ1 (the paper)."""
    @property
    def observer_lag_compensation(self) -> bool:
        """Observer speed ω̂1 plus T2S-1's low-passed Kp·e (fado's improvement); False = the paper's ω̂1."""
    @property
    def observer_gain_period(self) -> float:
        """Period (s) at which the observer's gains are recomputed and held in between; 0 = every sample (the paper)."""
    @property
    def rs_adaptation(self) -> bool:
        """Adapt R̂s online (fado's extension, default True; False = the paper)."""
    @property
    def rs_adaptation_rate(self) -> float:
        """Rate γ of the R̂s adaptation while turning, in 1/s."""
    @property
    def rs_adaptation_excitation_floor(self) -> float:
        """Excitation floor χ0 of the R̂s adaptation."""
    @property
    def rs_adaptation_min_ratio(self) -> float:
        """Lower bound of the adapted R̂s as a multiple of the machine's rs."""
    @property
    def rs_adaptation_max_ratio(self) -> float:
        """Upper bound of the adapted R̂s as a multiple of the machine's rs."""
    @property
    def flux_linkage_adaptation_rate(self) -> float:
        """Rate of the λ̂f learning where R̂s is unobservable, in 1/s (0 = fixed λ̂f)."""
    @property
    def offset_adaptation_rate(self) -> float:
        """With rs_adaptation: rate of the integrand-offset (voltage-offset) estimate while turning, in 1/s (0 = off)."""
    @property
    def standstill_angle_rate(self) -> float:
        """With rs_adaptation: rate at which λ̂r turns towards the current at standstill under the eq. (23) injection, in 1/s (0 = off)."""
    @property
    def limiter_recentring(self) -> bool:
        """In limiter mode, re-centre the common mode of λ1 and D̂ (fado's improvement)."""
    @property
    def plausible_current_ratio(self) -> float:
        """Samples whose α-β current magnitude reaches this × the rated current are refused."""
    @property
    def plausible_voltage_ratio(self) -> float:
        """Samples whose α-β voltage magnitude reaches this × the DC-link voltage are refused."""
    @property
    def plausible_current_step_ratio(self) -> float:
        """Bound on |Δi| in units of (plausible voltage)·ts/L̂q per sample (0 = off)."""
    @property
    def lock_flux_low_ratio(self) -> float:
        """Loss of lock: |λ̂r|/λ̂f below this is a symptom below the mode hand-over band."""
    @property
    def lock_flux_low_fast_ratio(self) -> float:
        """Loss of lock: |λ̂r|/λ̂f below this is a symptom from the mode hand-over band up."""
    @property
    def lock_flux_high_ratio(self) -> float:
        """Loss of lock: |λ̂r|/λ̂f above this is a symptom (0: off)."""
    @property
    def lock_innovation_limit(self) -> float:
        """Loss of lock: T2S-1 innovation above this (rad) is a symptom."""
    @property
    def lock_detection_time(self) -> float:
        """Loss of lock: net symptomatic time (s) before lock = 2 (0 = off)."""
    @property
    def lock_heal_time(self) -> float:
        """Loss of lock: net clean time (s) after which lock = 2 clears (a live status)."""
    @property
    def lock_limiter_clamping(self) -> bool:
        """Loss of lock: limiter clamping in limiter mode is a symptom."""
    @property
    def lock_handover_count(self) -> float:
        """Loss of lock: this many mode hand-overs per lock_handover_time is a symptom (0: off)."""
    @property
    def lock_handover_time(self) -> float:
        """Loss of lock: time constant (s) of the mode hand-over count's decay."""

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
    motor: str | Machine | None = None,
) -> SimResult:
    """Run a scenario (the paper's Fig. 8–12, or one scaled by the motor's ratings) on the simulated drive (GIL released)."""

def scenarios() -> list[str]:
    """The scenario names."""

def describe_scenario(scenario: str) -> dict[str, str]:
    """Name, title, profile and pass criterion of a scenario."""

def default_config(
    scenario: str = "fig11", averaged: bool = False, *, motor: str | Machine | None = None
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
