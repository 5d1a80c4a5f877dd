"""setuptools driving CMake for `pip install .`: builds the `_granoscope` target (and only what
it needs) in build/pip (or in GRANOSCOPE_CMAKE_BUILD_DIR, e.g. an existing build/) and installs
python/granoscope/ with the compiled module. See docs/python.md."""
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("GRANOSCOPE_CMAKE_BUILD_DIR")
        if not build:  # a build folder of its own, without the tests
            build = os.path.join(ROOT, "build", "pip")
            subprocess.check_call(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                                   "-DGRANOSCOPE_TESTS=OFF", "-DPython_EXECUTABLE=" + sys.executable])
        subprocess.check_call(["cmake", "--build", build, "--target", "_granoscope", "-j",
                               str(os.cpu_count() or 2)])
        built = os.path.join(build, "python", "granoscope")
        target = os.path.dirname(self.get_ext_fullpath(ext.name))
        os.makedirs(target, exist_ok=True)
        for name in os.listdir(built):
            if name.startswith("_granoscope") and name.endswith(".so"):
                shutil.copy2(os.path.join(built, name), self.get_ext_fullpath(ext.name))


setup(
    packages=["granoscope"],
    package_dir={"granoscope": "python/granoscope"},
    ext_modules=[CMakeExtension("granoscope._granoscope")],
    cmdclass={"build_ext": CMakeBuild},
)
