"""Heat and voltage of an emulated chain: servos warm with the load they hold and cool towards ambient, the
supply sags once faults start, and a servo reports overheating or an input voltage error at its own limits
(its Temperature Limit and Min/Max Voltage Limit registers). A mixin of
:class:`~gaitbot.emulator.chain.EmulatedChain`."""

from __future__ import annotations

import math

from gaitbot.emulator.units import Servo
from gaitbot.servos.health import encode_load


class HeatAndSupply:
    """The supply's voltage now, the servos' temperatures, and the faults they cause."""

    def supply_now_v(self) -> float:
        """The supply's voltage now: ``supply_v`` less the sag since faults became active."""
        self.faults_active()
        if self.faults_since_s is None or not self.config.voltage_sag_v_per_s:
            return self.supply_v
        return max(0.0, self.supply_v - self.config.voltage_sag_v_per_s * (self.now_s - self.faults_since_s))

    def _natural_kinds(self, unit: Servo) -> set[str]:
        """What the servo itself reports: overheating at its Temperature Limit, input voltage outside its limits."""
        layout, table, order = unit.layout, unit.table, unit.model.byte_order
        kinds = set()
        if unit.temperature_c >= table[layout.temperature_limit_addr]:
            kinds.add("overheating")
        tenths = self._supply_v * 10
        (low, low_size), (high, high_size) = layout.min_voltage, layout.max_voltage
        if tenths < int.from_bytes(table[low:low + low_size], order) or \
                tenths > int.from_bytes(table[high:high + high_size], order):
            kinds.add("voltage")
        return kinds

    def _warm(self, unit: Servo, dt_s: float, torque: bool) -> None:
        if dt_s > 0.0:
            heat = self.config.heat
            load = unit.load_pct / 100.0 if torque else 0.0
            equilibrium_c = heat.ambient_c + heat.heat_c_per_s * load * load * heat.cool_time_s
            unit.temperature_c = equilibrium_c + (unit.temperature_c - equilibrium_c) * math.exp(
                -dt_s / heat.cool_time_s)
        shown = (int(round(unit.temperature_c)), int(round(self._supply_v * 10)), torque, unit.load_pct)
        if shown == unit.shown:
            return  # the registers already say so
        unit.shown = shown
        block, table, order = unit.block, unit.table, unit.model.byte_order
        table[block.temperature.address] = max(0, min(255, shown[0]))
        size = block.voltage.size
        table[block.voltage.address:block.voltage.address + size] = \
            max(0, min(shown[1], (1 << (8 * size)) - 1)).to_bytes(size, order)
        if block.load is not None:
            raw = encode_load(unit.load_pct if torque else 0.0, block.load_encoding, block.load.size)
            table[block.load.address:block.load.address + block.load.size] = raw.to_bytes(block.load.size, order)
