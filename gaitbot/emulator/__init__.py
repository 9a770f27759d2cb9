"""A servo chain in time, with faults, heat, a sagging supply and a scripted hand: the engine behind
tools/servo_emulator.py.

``ServoEmulator(EmulatorConfig(...))`` opens a pty pair and answers on it like a chain of Dynamixel
or Feetech servos (``start()`` serves it on a background thread; ``path`` is the device a driver
opens; ``stop()``, ``chain``, ``wait_closed()``). ``EmulatedChain`` is the chain alone, fed with
``receive(data, now_s)`` and read with ``due(now_s)``, for tests without a pty.

Instruction parsing, framing and the control tables are the mock's (gaitbot.bus.dry_run.DryRunPort, the
chain a dry run talks to) and the vendors' (gaitbot.servos); this module adds time (return delay,
byte time, motion at the no-load speed), the Status Return Level, the instructions a dry run never
sends (reg write, action, reboot, bulk read/write), faults (silent, late, corrupt, error bits, a port
that disappears), a hand that moves servos whose torque is off, and what bring-up needs:

* **servos as units**, each with its own control table: an ID or Baud Rate write (EEPROM) takes effect
  at once, so the servo answers at its new id and rate; EEPROM writes persist over ``power_cycle()``
  (Feetech: only those made with the Lock register at 0); a Protocol 2.0 servo refuses an EEPROM write
  while its torque is on (Access Error), as the e-Manual says;
* **the line's baud rate**: a servo hears only a host set to its rate (the pty's speed, read from the
  master side), and a reply sent at another rate is lost;
* **factory-fresh chains** (every servo at id 1 and its factory rate), connected one at a time
  (``plug_next()``, or Enter on the command line), and **collisions**: servos answering one packet at
  once (two at one id; Feetech and Protocol 1.0 broadcast pings) send one damaged status packet;
* **heat**: a servo with torque on holding a load (``loads``, % of its maximum torque) warms by
  ``heat_c_per_s`` x load^2 and cools towards ambient with time constant ``cool_time_s``; at its Temperature
  Limit it reports overheating and switches torque off, as the servos' factory Shutdown setting does;
* **the supply**: ``supply_v`` volts, falling by ``voltage_sag_v_per_s`` once faults are active; under a
  servo's Min Voltage Limit it reports an input voltage error (and keeps driving, as X servos do).

A development tool, not the runtime: a room of its own above the bus (the import contract in
pyproject.toml), used by the app and the tests, imported by nothing below. It knows no gait: a hand's
motion comes as ticks (``Hand``), which the app layer makes from a trajectory.

Modules: ``config`` (EmulatorConfig and the hand), ``units`` (one servo: its table and layout), ``chain``
(the chain in time: routing, motion, replies), ``instructions`` (what a dry run never sends), ``faults``
(injected faults and collisions), ``heat`` (heat and the supply's voltage), ``hand`` (the scripted hand),
``pty`` (the chain served on a pseudo-terminal). docs/emulator.md describes it; gaitbot.app.emulator is
its command line.
"""


from gaitbot.emulator.chain import EmulatedChain
from gaitbot.emulator.config import FAULT_KINDS, EmulatorConfig, Faults, Hand, Heat, hand_from_ticks
from gaitbot.emulator.pty import ServoEmulator, line_rate, set_line_rate
from gaitbot.emulator.units import Servo

__all__ = ["FAULT_KINDS", "EmulatedChain", "EmulatorConfig", "Faults", "Hand", "Heat", "Servo", "ServoEmulator",
           "hand_from_ticks", "line_rate", "set_line_rate"]
