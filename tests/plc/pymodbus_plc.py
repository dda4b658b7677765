#!/usr/bin/python3
"""An independent PLC for facet's PLC tests: a pymodbus TCP server plus a scan loop that acts
like a PLC program on the same registers.

    pymodbus_plc.py --config plc.json --port 5020            # the PLC serves the registers
    pymodbus_plc.py --config plc.json --port 5020 --client   # the daemon serves, the PLC polls

plc.json (wire addresses, i.e. zero-based as sent on the wire):
    {"coils": 64, "registers": 256,
     "signals": {"trigger": {"table": "coil", "address": 0, "bit": -1}, "result_ack": ...,
                 "busy": ..., "result_valid": ..., "pass": ..., "missed_trigger": ...,
                 "error": ..., "completed_toggle": ...,
                 "inspection_counter": {"table": "register", "address": 20}, "error_code": ...},
     "results": [{"name": "d", "address": 100, "type": "float32", "word_order": "CDAB",
                  "factor": 1.0}],
     "auto_ack": true, "mode": "triggered"}   (mode "free_run": report each new counter)
    "report_writes": true (free run): report a result on every write of the inspection counter
    as the daemon's request arrives, repeats included, instead of scanning for a changed counter,
    so that no result escapes between two scans; and emit {"event": "first_write"} on the first
    write of any kind after start (a reconnected daemon).

stdin commands, one per line: "trigger" (raise the trigger; cleared when busy or result valid
rises, or after 5 s; 0.5 s when raised while busy), "untrigger" (clear it now), "report <signal>" (emit {"event": "report", ...} with its value),
"set_register <address> <value>", "quit".
stdout: one JSON object per line: {"event": "listening", "port": P}, then
{"event": "result", ...} per result valid rising edge (decoded here with struct, independently
of facet's encoder, plus the raw words), {"event": "missed_trigger"} per rising edge.
"listening", "first_write" and "result" carry "t": time.monotonic() (CLOCK_MONOTONIC, the clock
of C++'s steady_clock on Linux), so a test can time them against its own events.
"""
import argparse
import asyncio
import json
import math
import logging
import struct
import sys
import threading
import time

try:
    import pymodbus
    from pymodbus.datastore import (ModbusSequentialDataBlock, ModbusServerContext,
                                    ModbusSlaveContext)
    from pymodbus.client import ModbusTcpClient
    from pymodbus.server import StartAsyncTcpServer
except ImportError as error:  # the C++ test turns this into a failure with this message
    print(json.dumps({"event": "error",
                      "message": f"pymodbus is not installed for /usr/bin/python3 ({error}); "
                                 "run deploy/install-deps.sh"}), flush=True)
    sys.exit(3)

logging.getLogger("pymodbus").setLevel(logging.CRITICAL)  # keeps kill/restart runs quiet
COILS, HOLDING = 1, 3  # function codes selecting pymodbus' tables


def json_safe(obj):
    """NaN (an output written as "not measured") becomes null: JSON has no NaN."""
    if isinstance(obj, float) and math.isnan(obj):
        return None
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [json_safe(v) for v in obj]
    return obj


def emit(obj):
    print(json.dumps(json_safe(obj), allow_nan=False), flush=True)


WRITE_CODES = (5, 6, 15, 16)  # write single/multiple coils/registers, as requests arrive


class WatchedSlave(ModbusSlaveContext):
    """The server's tables, telling the PLC program about the daemon's writes as they land (before
    the server answers them): a result counted as written by the daemon was seen here."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.on_write = lambda fc, address, count: None

    def setValues(self, fc_as_hex, address, values):  # pylint: disable=invalid-name
        super().setValues(fc_as_hex, address, values)
        if fc_as_hex in WRITE_CODES:
            self.on_write(fc_as_hex, address, len(values))


class Plc:
    def __init__(self, config, slave):
        self.config = config
        self.slave = slave
        self.signals = config.get("signals", {})
        self.trigger_since = None
        self.trigger_while_busy = False
        self.last = {}
        self.wrote = False

    def flag(self, name):
        at = self.signals.get(name)
        if at is None:
            return False
        if at["table"] == "coil":
            return bool(self.slave.getValues(COILS, at["address"], 1)[0])
        word = self.slave.getValues(HOLDING, at["address"], 1)[0]
        return bool((word >> at["bit"]) & 1) if at.get("bit", -1) >= 0 else word != 0

    def set_flag(self, name, value):
        at = self.signals[name]
        if at["table"] == "coil":
            self.slave.setValues(COILS, at["address"], [bool(value)])
            return
        bit = at.get("bit", -1)
        if bit < 0:
            self.slave.setValues(HOLDING, at["address"], [1 if value else 0])
            return
        word = self.slave.getValues(HOLDING, at["address"], 1)[0]
        word = word | (1 << bit) if value else word & ~(1 << bit)
        self.slave.setValues(HOLDING, at["address"], [word])

    def number(self, name):
        at = self.signals.get(name)
        return None if at is None else self.slave.getValues(HOLDING, at["address"], 1)[0]

    def decode(self, output):
        words = self.slave.getValues(HOLDING, output["address"], 2 if output["type"] in (
            "int32", "scaled_int32", "float32") else 1)
        kind = output["type"]
        if kind in ("int16", "scaled_int16"):
            value = struct.unpack(">h", struct.pack(">H", words[0]))[0]
        else:
            w0, w1 = words
            order = output.get("word_order", "ABCD").upper()
            big = lambda w: struct.pack(">H", w)
            little = lambda w: struct.pack("<H", w)
            abcd = {"ABCD": big(w0) + big(w1), "CDAB": big(w1) + big(w0),
                    "BADC": little(w0) + little(w1), "DCBA": little(w1) + little(w0)}[order]
            value = struct.unpack(">f" if kind == "float32" else ">i", abcd)[0]
        if kind.startswith("scaled"):
            value = value / output["factor"]
        return value, list(words)

    def read_result(self):
        values, raw = {}, {}
        for output in self.config.get("results", []):
            values[output["name"]], raw[output["name"]] = self.decode(output)
        return {"event": "result", "counter": self.number("inspection_counter"),
                "pass": self.flag("pass"), "error": self.flag("error"),
                "error_code": self.number("error_code"),
                "toggle": self.flag("completed_toggle"), "values": values, "raw": raw}

    def edge(self, name):
        now = self.flag(name)
        rising = now and not self.last.get(name, False)
        falling = not now and self.last.get(name, False)
        self.last[name] = now
        return rising, falling

    def on_write(self, fc, address, count):
        if not self.wrote:
            self.wrote = True
            emit({"event": "first_write", "t": time.monotonic()})
        at = self.signals.get("inspection_counter")
        if (self.config.get("report_writes") and self.config.get("mode") == "free_run"
                and at is not None and fc in (6, 16) and address <= at["address"] < address + count):
            emit(dict(self.read_result(), t=time.monotonic()))

    def scan(self):
        if self.config.get("mode") == "free_run":
            if self.config.get("report_writes"):
                return  # on_write reports
            # No trigger, no ack: a new inspection counter announces a result.
            counter = self.number("inspection_counter")
            if counter != self.last.get("counter", 0):
                self.last["counter"] = counter
                emit(self.read_result())
            return
        # The trigger is held until the daemon answers, as a PLC program does: busy rises, or
        # (when the inspection was quicker than this scan) a result arrives. A trigger raised
        # while busy (a deliberate missed trigger) is a 0.5 s pulse; any other gives up after 5 s,
        # long enough for a link starved of CPU on a loaded machine.
        busy_rising, _ = self.edge("busy")
        valid_rising, valid_falling = self.edge("result_valid")
        hold = 0.5 if self.trigger_while_busy else 5.0
        if self.trigger_since is not None and (busy_rising or valid_rising or
                                               time.monotonic() - self.trigger_since > hold):
            self.set_flag("trigger", False)
            self.trigger_since = None
        if valid_rising:
            emit(self.read_result())
            if self.config.get("auto_ack", True):
                self.set_flag("result_ack", True)
        if valid_falling and "result_ack" in self.signals:
            self.set_flag("result_ack", False)
        missed_rising, _ = self.edge("missed_trigger")
        if missed_rising:
            emit({"event": "missed_trigger"})

    def command(self, line):
        if line == "trigger":
            self.trigger_while_busy = "busy" in self.signals and self.flag("busy")
            self.set_flag("trigger", True)
            self.trigger_since = time.monotonic()
        elif line == "untrigger":
            self.set_flag("trigger", False)
            self.trigger_since = None
        elif line.startswith("report "):
            # "report <signal>": the current value of a mapped signal, as the PLC sees it
            name = line.split()[1]
            at = self.signals[name]
            value = (self.flag(name) if at["table"] == "coil" or at.get("bit", -1) >= 0
                     else self.number(name))
            emit({"event": "report", "signal": name, "value": value})
        elif line.startswith("set_register "):
            _, address, value = line.split()
            self.slave.setValues(HOLDING, int(address), [int(value)])


class ClientTables:
    """The daemon's registers seen through a pymodbus client: the PLC program polls them."""

    def __init__(self, client):
        self.client = client

    def getValues(self, fc, address, count=1):  # pylint: disable=invalid-name
        reply = (self.client.read_coils(address, count) if fc == COILS
                 else self.client.read_holding_registers(address, count))
        if reply.isError():
            raise RuntimeError(f"read {fc} {address}: {reply}")
        return reply.bits[:count] if fc == COILS else reply.registers

    def setValues(self, fc, address, values):  # pylint: disable=invalid-name
        reply = (self.client.write_coil(address, values[0]) if fc == COILS
                 else self.client.write_registers(address, values))
        if reply.isError():
            raise RuntimeError(f"write {fc} {address}: {reply}")


class StdinCommands:
    """The test's commands, one per line on stdin, read on a thread of their own so that the scan
    loop never blocks; end of input becomes "quit"."""

    def __init__(self):
        self.lines = []
        self.lock = threading.Lock()
        threading.Thread(target=self.read, daemon=True).start()

    def read(self):
        for line in sys.stdin:
            with self.lock:
                self.lines.append(line.strip())
        with self.lock:
            self.lines.append("quit")

    def take(self):
        with self.lock:
            pending, self.lines = self.lines, []
        return pending


def run_client(config, port):
    client = ModbusTcpClient("127.0.0.1", port=port)
    if not client.connect():
        emit({"event": "error", "message": f"cannot connect to 127.0.0.1:{port}"})
        sys.exit(4)
    emit({"event": "connected", "port": port, "pymodbus": pymodbus.__version__})
    plc = Plc(config, ClientTables(client))
    commands = StdinCommands()
    while True:
        for line in commands.take():
            if line == "quit":
                client.close()
                return
            plc.command(line)
        plc.scan()
        time.sleep(0.001)


async def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--config", required=True)
    parser.add_argument("--port", type=int, required=True)
    parser.add_argument("--client", action="store_true")
    args = parser.parse_args()
    with open(args.config, encoding="utf-8") as f:
        config = json.load(f)
    if args.client:
        run_client(config, args.port)
        return

    slave = WatchedSlave(co=ModbusSequentialDataBlock(0, [False] * config.get("coils", 64)),
                         hr=ModbusSequentialDataBlock(0, [0] * config.get("registers", 256)),
                         zero_mode=True)
    plc = Plc(config, slave)
    slave.on_write = plc.on_write  # before the server starts: it sees every write
    context = ModbusServerContext(slaves=slave, single=True)
    server = await StartAsyncTcpServer(context=context, address=("127.0.0.1", args.port),
                                       allow_reuse_address=True, defer_start=True)
    serving = asyncio.create_task(server.serve_forever())
    await server.serving
    emit({"event": "listening", "port": args.port, "pymodbus": pymodbus.__version__,
          "t": time.monotonic()})

    commands = StdinCommands()
    while True:
        for line in commands.take():
            if line == "quit":
                serving.cancel()
                return
            plc.command(line)
        plc.scan()
        await asyncio.sleep(0.0005)


if __name__ == "__main__":
    try:
        asyncio.run(main())
    except (KeyboardInterrupt, asyncio.CancelledError):
        pass
