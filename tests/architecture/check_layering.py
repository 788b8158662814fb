#!/usr/bin/env python3
"""The library's include graph follows the modules of the identification loop (README
"Architecture", docs/design.md section 2): every #include of a dynid header from
include/dynid/<module>/ or src/<module>/ must name a module that <module> may include, and the
modules that sit below identify() may take from identification/ only the run record and the
pipeline stages. Exits 1 with one line per offending include; prints "N passed, 0 failed"."""

import os
import re
import sys

BELOW_LOOP = {"common", "model", "dynamics", "regressor", "identifiability", "signal"}
# module -> the modules it may include (besides itself).
MAY_INCLUDE = {
    "common": set(),
    "model": {"common"},
    "dynamics": {"common", "model"},
    "regressor": {"common", "model", "dynamics", "signal"},
    "identifiability": {"common", "model", "dynamics", "regressor"},
    "signal": {"common"},
    # Solvers and statistics; the on-line estimator builds its own regressor.
    "estimation": {"common", "model", "dynamics", "regressor", "identifiability"},
    "excitation": BELOW_LOOP | {"estimation"},
    "identification": BELOW_LOOP | {"estimation", "closed_loop", "io"},
    "experiments": BELOW_LOOP | {"estimation", "identification"},
    "load": BELOW_LOOP | {"estimation", "identification"},
    "closed_loop": BELOW_LOOP | {"estimation", "identification"},
    "io": BELOW_LOOP | {"identification", "closed_loop"},
    "sim": BELOW_LOOP | {"estimation", "io", "load"},
    "physical": BELOW_LOOP | {"estimation", "identification", "io"},
    "report": None,  # stands on everything
    "workflow": None,
}
# What the modules below identify() may include from identification/: the run record and its
# preparation, the pipeline stages and the options they share.
IDENTIFICATION_BASE = {
    "record.hpp", "processed_slice.hpp", "pipeline.hpp", "known_friction.hpp",
    "integral_options.hpp", "integral_equations.hpp", "outlier_options.hpp", "outliers.hpp",
}
BELOW_IDENTIFY = {"experiments", "load", "closed_loop", "io"}
# Headers of those modules that take identify()'s options or result, and why.
IDENTIFY_USERS = {
    "include/dynid/closed_loop/closed_loop.hpp",         # identify_repeated() runs identify()
    "include/dynid/closed_loop/maximum_likelihood.hpp",  # the ML stage takes IdentifyOptions
    "src/closed_loop/maximum_likelihood.cpp",
    "include/dynid/load/load_identification.hpp",        # a reference IdentificationResult
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"(?:dynid/)?([a-z_]+)/([a-z_]+\.hpp)"', re.M)


def main(root):
    failures, checked = [], 0
    for top in ("include/dynid", "src"):
        for folder, _, files in os.walk(os.path.join(root, top)):
            module = os.path.relpath(folder, os.path.join(root, top)).split(os.sep)[0]
            if module not in MAY_INCLUDE:
                if module != ".":
                    failures.append(f"{folder}: module '{module}' is not in the layering table")
                continue
            for name in sorted(files):
                path = os.path.join(folder, name)
                rel = os.path.relpath(path, root)
                with open(path, encoding="utf-8") as f:
                    text = f.read()
                for used, header in INCLUDE.findall(text):
                    checked += 1
                    if used in (module, "dynid") or MAY_INCLUDE[module] is None:
                        continue
                    if used not in MAY_INCLUDE[module]:
                        failures.append(f"{rel}: includes {used}/{header}; {module} may include "
                                        f"{', '.join(sorted(MAY_INCLUDE[module]))}")
                    elif (module in BELOW_IDENTIFY and used == "identification"
                          and header not in IDENTIFICATION_BASE and rel not in IDENTIFY_USERS):
                        failures.append(f"{rel}: includes identification/{header}; {module} stands "
                                        "on the run record and the pipeline stages, not identify()")
    for line in failures:
        print("error:", line)
    print(f"{checked - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
