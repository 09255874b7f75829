"""Build hook: compile the simulation kernel ahead of time when the package is built or installed.

Runs ``python -m fi_design.aot`` (numba's ahead-of-time compiler on the kernel's
source) and ships the extension module it writes, ``fi_design/_kernel_aot``,
in the wheel (an editable install finds it in the source tree). A build that
cannot compile it (no C compiler, say) still installs: the package then
compiles the same source with numba's JIT at first use, and says so in its
log.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from hatchling.builders.hooks.plugin.interface import BuildHookInterface


class KernelBuildHook(BuildHookInterface):
    """Compile ``fi_design/_kernel_aot`` for wheel and editable builds."""

    PLUGIN_NAME = "custom"

    def initialize(self, version: str, build_data: dict) -> None:
        if self.target_name != "wheel":
            return
        root = Path(self.root)
        package = root / "fi_design"
        for old in package.glob("_kernel_aot.*"):
            old.unlink()
        # the build environment reaches its packages (numba) through PYTHONPATH too: keep it
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            p for p in (str(root), os.environ.get("PYTHONPATH")) if p))
        env.pop("FI_DESIGN_KERNEL", None)
        self.app.display_info("compiling the simulation kernel ahead of time (about 15 s) ...")
        try:
            done = subprocess.run([sys.executable, "-m", "fi_design.aot"], cwd=root, env=env,
                                  capture_output=True, text=True, timeout=1800)
        except (OSError, subprocess.TimeoutExpired) as exc:
            self.app.display_warning(f"the kernel was not compiled ahead of time ({exc}); "
                                     "numba will compile it at first use")
            return
        built = sorted(package.glob("_kernel_aot.*"))
        if done.returncode != 0 or not built:
            tail = "\n".join((done.stderr or done.stdout).strip().splitlines()[-5:])
            self.app.display_warning("the kernel was not compiled ahead of time; numba will "
                                     f"compile it at first use:\n{tail}")
            return
        build_data["pure_python"] = False
        build_data["infer_tag"] = True
        if version != "editable":
            build_data["force_include"][str(built[-1])] = f"fi_design/{built[-1].name}"
