"""setup.py -- the package with its library: at install time libpound.so is
copied into the package (pound/libpound.so), so that `import pound` finds it
with no environment variable.  The library is $POUND_LIBRARY if set, else
../build/libpound.so of this source tree, built with `make shared` when it
is missing.  Without either (a copy of python/ alone), nothing is bundled
and pound looks for libpound.so.0 (make install) at import.  The metadata is
in pyproject.toml."""
import os
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def find_library():
    """The libpound.so to bundle, or None."""
    env = os.environ.get("POUND_LIBRARY")
    if env:
        return env
    built = os.path.join(ROOT, "build", "libpound.so")
    if not os.path.exists(built) and os.path.exists(os.path.join(ROOT, "Makefile")):
        subprocess.check_call(["make", "-C", ROOT, "--no-print-directory", "shared"])
    return built if os.path.exists(built) else None


class build_with_library(build_py):
    def run(self):
        super().run()
        lib = find_library()
        if lib:
            shutil.copyfile(os.path.realpath(lib),
                            os.path.join(self.build_lib, "pound", "libpound.so"))


class BinaryDistribution(Distribution):
    """A wheel with a shared library in it is for this platform only."""

    def has_ext_modules(self):
        return True


setup(cmdclass={"build_py": build_with_library}, distclass=BinaryDistribution)
