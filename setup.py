"""`pip install .`: builds impactdeck with CMake and installs, stripped, the Python module with its
type stubs, and the `impactdeck` command with its Gmsh plugins (docs/install.md, "pip").

The CMake build goes to build-pip/ in the checkout (or $IMPACTDECK_PIP_BUILD_DIR), configured as
scripts/build configures build/ (RelWithDebInfo, ccache with the checkout as base dir; a folder
beside build/, so that the compiler sees the same relative paths and objects compiled for any
checkout's build/ are cache hits) without tests and benchmarks, and only the module, the command
and the plugins are built. The staged install and setuptools' folders go to build-pip/pip/ (or
$IMPACTDECK_PIP_WORK). $IMPACTDECK_BUILD_TREE instead names a configured build tree to
take them from (e.g. build/, the one ctest runs): built there if out of date, nothing configured.
Either way `cmake --install --component python|command --strip` stages them, and the wheel takes
the staged files: the module and its stubs (and the plugins, which the module loads from beside
itself) into site-packages, the command and the plugins into bin/, the man page and the bash
completion into share/."""
import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
WORK = Path(os.environ.get("IMPACTDECK_PIP_WORK", ROOT / "build-pip" / "pip")).resolve()
STAGE = WORK / "stage"  # fixed here: data_files are named before anything is built
PLUGINS = ["libimpactdeck_gmsh_mesher.so", "libimpactdeck_gmsh_cad.so"]
TARGETS = ["impactdeck_python", "impactdeck", "impactdeck_cli_docs", "impactdeck_gmsh_mesher", "impactdeck_gmsh_cad"]


def run(*args, env=None):
    print("setup.py:", " ".join(str(a) for a in args), flush=True)
    subprocess.run([str(a) for a in args], check=True, env=env)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        env = dict(os.environ)
        env.setdefault("CCACHE_BASEDIR", str(ROOT))
        cmake = shutil.which("cmake") or "cmake"
        tree = os.environ.get("IMPACTDECK_BUILD_TREE")
        if tree:
            build = Path(tree).resolve()
            if not (build / "CMakeCache.txt").is_file():
                raise SystemExit(f"setup.py: IMPACTDECK_BUILD_TREE={tree} is not a configured CMake build tree")
        else:
            build = Path(os.environ.get("IMPACTDECK_PIP_BUILD_DIR", ROOT / "build-pip")).resolve()
            # The interpreter running pip is the one the module is built for.
            run(cmake, "-S", ROOT, "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
                "-DIMPACTDECK_BUILD_TESTS=OFF", "-DIMPACTDECK_BUILD_BENCH=OFF", f"-DPYTHON_EXECUTABLE={sys.executable}",
                env=env)
        jobs = os.environ.get("IMPACTDECK_JOBS", str(os.cpu_count() or 1))
        run(cmake, "--build", build, "-j", jobs, "--target", *TARGETS, env=env)
        shutil.rmtree(STAGE, ignore_errors=True)
        for component in ("python", "command"):
            run(cmake, "--install", build, "--prefix", STAGE, "--component", component, "--strip", env=env)
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        modules = sorted(STAGE.glob("lib/**/impactdeck*.so"))
        if [m.name for m in modules] != ["impactdeck" + suffix]:
            raise SystemExit(f"setup.py: expected one module impactdeck{suffix} (built for this Python) in {STAGE}, "
                             f"found {[m.name for m in modules]}: build the tree for {sys.executable}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(modules[0], target)
        shutil.copy2(modules[0].with_name("impactdeck.pyi"), target.with_name("impactdeck.pyi"))
        for plugin in PLUGINS:
            shutil.copy2(STAGE / "bin" / plugin, target.with_name(plugin))


setup(
    packages=[],  # one extension module, no Python package (no discovery in the checkout)
    py_modules=[],
    ext_modules=[Extension("impactdeck", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    data_files=[
        ("bin", [str(STAGE / "bin" / "impactdeck")] + [str(STAGE / "bin" / p) for p in PLUGINS]),
        ("share/man/man1", [str(STAGE / "share" / "man" / "man1" / "impactdeck.1")]),
        ("share/bash-completion/completions", [str(STAGE / "share" / "bash-completion" / "completions" / "impactdeck")]),
    ],
    # setuptools' own build folders beside CMake's, not in build/ (scripts/build's tree).
    options={"build": {"build_base": str(WORK / "setuptools")}, "egg_info": {"egg_base": str(WORK)}},
    zip_safe=False,
)
