# A Python script outside the scallop tree, run by tests/packaging_test.cmake on the module as
# installed into a temporary prefix (argv[1]): the whole plan of paper-1 with progress, then a
# second plan cancelled half way from its progress callback. Exits 1 on any unexpected figure.
import os
import sys

import scallop

prefix = os.path.realpath(sys.argv[1])
if not os.path.realpath(scallop.__file__).startswith(prefix + os.sep):
    sys.exit(f"scallop-consumer.py: imported {scallop.__file__}, not the module under {prefix}")

surface = scallop.example_surface("paper-1")
fractions = []
result = scallop.plan(surface, scallop_height=0.01, progress=lambda fraction, stage: fractions.append(fraction))
if fractions != sorted(fractions) or fractions[-1] != 1.0 or len(fractions) < 5:
    sys.exit(f"scallop-consumer.py: progress not monotone to 1: {fractions}")
if "G1" not in result.program or not result.max_gouge < 1e-3 or len(result.files()) != 7:
    sys.exit("scallop-consumer.py: unexpected plan result")

token = scallop.CancelToken()


def halfway(fraction, stage):
    if fraction > 0.5:
        token.cancel()


try:
    scallop.plan(surface, scallop_height=0.01, progress=halfway, cancel=token)
    sys.exit("scallop-consumer.py: the cancelled plan returned")
except scallop.Cancelled:
    pass
print(f"plan: {len(fractions)} progress reports, {len(result.passes)} passes, "
      f"{len(result.program)} bytes of G-code; cancelled half way")
