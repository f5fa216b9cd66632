#!/usr/bin/python3
# LinuxCNC "display" for the headless reference run: switches the simulated machine on, homes
# it, runs the program LREF_PROG and records the commanded joint positions of every servo
# period (halsampler, "SAMPLE X Y Z" per line) into LREF_OUT, then exits (LinuxCNC shuts down).
import os
import subprocess
import time

import linuxcnc

prog, out = os.environ["LREF_PROG"], os.environ["LREF_OUT"]
limit_s = float(os.environ.get("LREF_LIMIT_S", "180"))
s, c, e = linuxcnc.stat(), linuxcnc.command(), linuxcnc.error_channel()
errors = []


def wait(cond, limit_s):
    t0 = time.time()
    while time.time() - t0 < limit_s:
        s.poll()
        msg = e.poll()
        if msg:
            errors.append(str(msg[1]))
        if cond():
            return True
        time.sleep(0.005)
    return False


still = {"pos": None, "since": 0.0, "moved": False}


def finished():
    # The interpreter goes idle at M2; now and then it stays "reading" after the last move
    # has run (seen on a loaded machine), so an empty motion queue with the position still
    # for 3 s after the program moved also ends the run (the reference programs do not dwell).
    if s.interp_state == linuxcnc.INTERP_IDLE and s.queue == 0:
        return True
    pos = tuple(s.position[:3])
    if pos != still["pos"]:
        still["moved"] = still["pos"] is not None
        still["pos"], still["since"] = pos, time.time()
        return False
    return still["moved"] and s.queue == 0 and time.time() - still["since"] > 3.0


def fail(what):
    # LinuxCNC sends a display's output to a log it deletes: the verdict goes to OUT.status.
    with open(out + ".status", "w") as f:
        f.write("driver.py: " + what + "\n")
    sys.exit(1)


for attempt in range(10):  # task may still be starting (slowly on a loaded machine): ask again
    wait(lambda: False, 1.0)
    c.state(linuxcnc.STATE_ESTOP_RESET)
    c.wait_complete(10)
    c.state(linuxcnc.STATE_ON)
    c.wait_complete(10)
    if wait(lambda: s.task_state == linuxcnc.STATE_ON, 10):
        break
else:
    fail("machine did not switch on (task_state %d, estop %d)" % (s.task_state, s.estop))
c.home(-1)
if not wait(lambda: all(s.homed[i] for i in range(3)), 60):
    fail("machine did not home")
c.mode(linuxcnc.MODE_AUTO)
wait(lambda: s.task_mode == linuxcnc.MODE_AUTO, 10)
c.program_open(prog)
with open(out, "w") as f:
    rec = subprocess.Popen(["halsampler", "-t"], stdout=f)
    time.sleep(0.3)
    c.auto(linuxcnc.AUTO_RUN, 0)
    started = wait(lambda: s.interp_state != linuxcnc.INTERP_IDLE, 5)
    done = started and wait(finished, limit_s)
    time.sleep(0.3)
    rec.terminate()
    rec.wait()
if errors:
    fail("LinuxCNC error: " + "; ".join(errors))
if not done:
    fail(("program did not start" if not started else "program did not finish in %g s" % limit_s) +
         "; ".join([""] + errors) + " (interp %d, exec %d, queue %d)" % (s.interp_state, s.exec_state, s.queue))
with open(out + ".status", "w") as f:
    f.write("ok\n")
