"""Build of the optional native closed-loop step, rns_viz._closed_loop (C++ against pinocchio).

Everything else is in pyproject.toml. The extension is compiled against the headers of the exact
pinocchio, eigenpy and Boost releases that pyproject.toml pins for run time (their cmeel wheels
ship headers and libraries in ``cmeel.prefix``), plus Eigen's headers (cmeel-eigen, build only).
It is optional: without a C++ compiler the install still succeeds and rns_viz uses the pure
Python step (``rns_viz.sim.native.available()`` says which).

At run time the libraries it links (libpinocchio_default, libeigenpy, libboost_python) are the
ones ``import pinocchio`` has already loaded: rns_viz imports pinocchio before the extension.
"""

from __future__ import annotations

import sys
from pathlib import Path

from setuptools import Extension, setup


def cmeel_prefix() -> Path | None:
    """The cmeel.prefix folder of the environment building us (pip's isolated build env or the venv)."""
    for entry in sys.path:
        prefix = Path(entry) / "cmeel.prefix"
        if (prefix / "include" / "pinocchio").is_dir():
            return prefix
    return None


def native_extension() -> list[Extension]:
    prefix = cmeel_prefix()
    if prefix is None:
        print("rns_viz: pinocchio headers not found; building without the native step", file=sys.stderr)
        return []
    import numpy

    py = f"{sys.version_info.major}{sys.version_info.minor}"
    return [
        Extension(
            "rns_viz._closed_loop",
            sources=["rns_viz/_native/closed_loop.cpp"],
            include_dirs=[str(prefix / "include"), str(prefix / "include" / "eigen3"), numpy.get_include()],
            library_dirs=[str(prefix / "lib")],
            libraries=["pinocchio_default", "eigenpy", f"boost_python{py}"],
            define_macros=[
                ("NDEBUG", None),
                # what pinocchio's CMake target asks of its users
                ("PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION", None),
                ("BOOST_MPL_LIMIT_LIST_SIZE", "30"),
                ("BOOST_MPL_LIMIT_VECTOR_SIZE", "30"),
                ("BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", None),
                ("BOOST_FUSION_INVOKE_MAX_ARITY", "12"),
            ],
            # -g0: no debug information (Python's default -g makes a 140 MB library and a slower build)
            extra_compile_args=["-std=c++17", "-O2", "-g0", "-Wno-deprecated-declarations"],
            language="c++",
            optional=True,
        )
    ]


setup(ext_modules=native_extension())
