"""Build hook: compile the simulation kernel ahead of time when the package is built or installed.

Runs ``python -m fi_design.kernel.build``, the kernel's one build seam, and
ships the files it writes (it prints their paths, one a line) in the wheel
(an editable install finds them in the source tree). How the kernel is
compiled is that module's business alone. A build that cannot compile it (no
C compiler, say) still installs: the package then compiles the same source
with numba's JIT at first use, and says so in its log.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from hatchling.builders.hooks.plugin.interface import BuildHookInterface


class KernelBuildHook(BuildHookInterface):
    """Compile the simulation kernel for wheel and editable builds."""

    PLUGIN_NAME = "custom"

    def initialize(self, version: str, build_data: dict) -> None:
        if self.target_name != "wheel":
            return
        root = Path(self.root)
        # the build environment reaches its packages (numba) through PYTHONPATH too: keep it
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            p for p in (str(root), os.environ.get("PYTHONPATH")) if p))
        env.pop("FI_DESIGN_KERNEL", None)
        self.app.display_info("compiling the simulation kernel ahead of time (about 15 s) ...")
        try:
            done = subprocess.run([sys.executable, "-m", "fi_design.kernel.build"], cwd=root,
                                  env=env, capture_output=True, text=True, timeout=1800)
        except (OSError, subprocess.TimeoutExpired) as exc:
            self.app.display_warning(f"the kernel was not compiled ahead of time ({exc}); "
                                     "numba will compile it at first use")
            return
        # the files written, one a line (a compiler's own chatter is no file)
        built = [Path(line.strip()) for line in done.stdout.splitlines()
                 if line.strip() and Path(line.strip()).is_file()]
        if done.returncode != 0 or not built:
            tail = "\n".join((done.stderr or done.stdout).strip().splitlines()[-5:])
            self.app.display_warning("the kernel was not compiled ahead of time; numba will "
                                     f"compile it at first use:\n{tail}")
            return
        build_data["pure_python"] = False
        build_data["infer_tag"] = True
        if version != "editable":
            for path in built:
                build_data["force_include"][str(path)] = path.resolve().relative_to(
                    root.resolve()).as_posix()
