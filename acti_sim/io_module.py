"""The I/O module of the base: numbered inputs and outputs, declared in a YAML file (the spec's
io.xml). An input reads a constant, the bumper, or an output (a loop-back wire); outputs keep the
last value written. Output id 0 is reserved for the unit itself."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable

import yaml

DEFAULT_IO_CONFIG = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                 "config", "vehicle_io.yaml")
RESERVED_OUTPUT = 0
WORD = 0xFFFFFFFF


@dataclass(frozen=True)
class Port:
    id: int
    name: str
    source: str = ""      # inputs: "bumper", "output:<id>", or "" (a constant)
    value: int = 0        # initial value (outputs) or the constant (inputs)


class IoModule:
    """Reads and writes 32-bit port values by id; `sensors` supplies named live inputs."""

    def __init__(self, inputs: list[Port], outputs: list[Port],
                 sensors: dict[str, Callable[[], int]] | None = None) -> None:
        self.inputs = {p.id: p for p in inputs}
        self.outputs = {p.id: p for p in outputs}
        self.values = {p.id: p.value & WORD for p in outputs}
        self.sensors = sensors or {}
        for p in inputs:
            if p.source.startswith("output:") and int(p.source[7:]) not in self.outputs:
                raise ValueError(f"I/O input {p.id} reads output {p.source[7:]}, which is not declared")
            if p.source and not p.source.startswith("output:") and p.source not in self.sensors:
                raise ValueError(f"I/O input {p.id}: unknown source {p.source!r}")

    @classmethod
    def load(cls, path: str, sensors: dict[str, Callable[[], int]] | None = None) -> "IoModule":
        path = path or DEFAULT_IO_CONFIG
        try:
            with open(path) as f:
                doc = yaml.safe_load(f) or {}

            def ports(key: str) -> list[Port]:
                return [Port(int(p["id"]), str(p.get("name", "")), str(p.get("source", "")),
                             int(p.get("value", 0))) for p in doc.get(key, [])]
            inputs, outputs = ports("inputs"), ports("outputs")
        except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError, AttributeError) as e:
            raise ValueError(f"io_config {path}: not an I/O description "
                             f"({type(e).__name__}: {e})") from None
        return cls(inputs, outputs, sensors)

    def read(self, ioid: int) -> int | None:
        """The input's value, or None for an unknown id."""
        port = self.inputs.get(ioid)
        if port is None:
            return None
        if port.source.startswith("output:"):
            return self.values[int(port.source[7:])]
        if port.source:
            return int(self.sensors[port.source]()) & WORD
        return port.value & WORD

    def write(self, ioid: int, output: int, mask: int) -> bool:
        """Set the bits of `mask` to those of `output`; False for an unknown or reserved id."""
        if ioid == RESERVED_OUTPUT or ioid not in self.outputs:
            return False
        old = self.values[ioid]
        self.values[ioid] = ((old & ~mask) | (output & mask)) & WORD
        return True
