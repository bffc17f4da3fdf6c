"""The base's battery: a charge that drains with use and the voltage it shows (V, W, s)."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class BatteryModel:
    """A 48 V class pack: open-circuit voltage linear in the charge, an internal resistance."""
    capacity_wh: float = 960.0
    full_voltage: float = 54.6
    empty_voltage: float = 42.0
    internal_resistance: float = 0.08     # Ω


class Battery:
    """State of charge in [0, 1]; `drain(power, dt)` takes energy, `voltage` sags under load."""

    def __init__(self, model: BatteryModel, charge: float = 1.0) -> None:
        if model.capacity_wh <= 0 or model.full_voltage <= model.empty_voltage:
            raise ValueError("battery: capacity must be > 0 and full voltage above empty voltage")
        self.model = model
        self.charge = min(1.0, max(0.0, charge))
        self.power = 0.0

    @property
    def open_circuit_voltage(self) -> float:
        m = self.model
        return m.empty_voltage + (m.full_voltage - m.empty_voltage) * self.charge

    @property
    def voltage(self) -> float:
        """Terminal voltage under the present load."""
        ocv = self.open_circuit_voltage
        return ocv - self.model.internal_resistance * self.power / ocv

    def drain(self, power: float, dt: float) -> None:
        """Deliver `power` W for `dt` s."""
        self.power = max(0.0, power)
        self.charge = max(0.0, self.charge - self.power * dt / (3600.0 * self.model.capacity_wh))


class VoltageLevel:
    """A voltage alarm level with hysteresis: tripped below `level`, released only at
    `level + band` or above, so a load that drops (and lets the voltage recover a little)
    does not end the alarm of a battery that is still at its limit."""

    def __init__(self, level: float, band: float) -> None:
        if band < 0:
            raise ValueError(f"battery: the hysteresis band is {band} V, it must be >= 0")
        self.level, self.band = level, band
        self.tripped = False

    def describe(self, voltage: float) -> str:
        """Why the level is tripped at this voltage (below it, or not yet back above its band)."""
        if voltage < self.level:
            return f"{voltage:.2f} V (below {self.level:g} V)"
        return f"{voltage:.2f} V (tripped below {self.level:g} V, released at {self.level + self.band:g} V)"

    def update(self, voltage: float) -> bool:
        """Whether the level is tripped at this voltage."""
        if voltage < self.level:
            self.tripped = True
        elif voltage >= self.level + self.band:
            self.tripped = False
        return self.tripped
