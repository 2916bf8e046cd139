# Streams a G-code file with Printrun's printcore (Debian's python3-printrun) and prints
# "<commands> <seconds>": the peer in tests/bench/link_bench.sh.
import sys
import time

from printrun import gcoder
from printrun.printcore import printcore

port, path = sys.argv[1], sys.argv[2]
with open(path) as f:
    lines = [line.rstrip("\n") for line in f]
gcode = gcoder.LightGCode(lines)
commands = sum(1 for line in lines if line.split(";")[0].strip())
p = printcore(port, 250000)
t = time.time()
while not p.online:
    time.sleep(0.01)
    if time.time() - t > 10:
        sys.exit("printcore: the printer did not answer")
start = time.time()
p.startprint(gcode)
while p.printing:
    time.sleep(0.005)
elapsed = time.time() - start
p.disconnect()
print("%d %.3f" % (commands, elapsed))
