"""Build files of a C package: a Makefile and a CMakeLists.txt with the same flags.

Both build the static and shared library ``lib<name>``, the example and the harness with
``WARNINGS`` and optimisation (``-O2``; CMake: the Release build type unless another is
chosen). CMake also installs the libraries, headers, README and manifest, and a package
configuration, so that another project finds it with ``find_package(<name>)`` and links
``<name>::<name>`` (static) or ``<name>::<name>_shared``.
"""

from __future__ import annotations

__all__ = ["WARNINGS", "cmake_lists", "makefile"]

WARNINGS = ("-Wall", "-Wextra", "-pedantic")


def make_products(name: str) -> tuple[str, ...]:
    """The files ``make`` writes in package ``name``'s folder (what ``make clean`` removes): uvsym's own
    output too, so that writing the package again over a built one is not refused."""
    return (f"src/{name}_casadi.o", f"src/{name}.o", "main.o", "harness.o", f"lib{name}.a", f"lib{name}.so",
            "example", "harness", "target/harness.elf")


def makefile(name: str, target=None) -> str:
    """The package's Makefile (``make``; ``make CFLAGS=...`` to change flags); with a
    :class:`~uvsym.codegen.targets.Target`, its ``target`` and ``run-target`` rules too."""
    from uvsym.codegen.targets import target_make_rules

    products = make_products(name)
    rules = target_make_rules(name, target) if target is not None else ""
    return f"""# Builds lib{name}.a, lib{name}.so, the example and the harness.
# CFLAGS may be overridden freely (e.g. make CFLAGS="-std=c99 -O2 {' '.join(WARNINGS)} -Werror -fPIC");
# include paths live in CPPFLAGS.
CC ?= cc
CFLAGS ?= -std=c99 -O2 {' '.join(WARNINGS)} -fPIC
CPPFLAGS += -Iinclude
LDLIBS += -lm
OBJ = {' '.join(products[:2])}

all: lib{name}.a lib{name}.so example harness

lib{name}.a: $(OBJ)
\t$(AR) rcs $@ $(OBJ)

lib{name}.so: $(OBJ)
\t$(CC) $(CFLAGS) -shared -o $@ $(OBJ) $(LDLIBS)

example: main.o lib{name}.a
\t$(CC) $(CFLAGS) -o $@ main.o lib{name}.a $(LDLIBS)

harness: harness.o lib{name}.a
\t$(CC) $(CFLAGS) -o $@ harness.o lib{name}.a $(LDLIBS)

%.o: %.c
\t$(CC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

clean:
\trm -f $(OBJ) main.o harness.o lib{name}.a lib{name}.so example harness

.PHONY: all clean
{rules}"""


def cmake_lists(name: str) -> str:
    """The package's CMakeLists.txt (module docstring)."""
    return f"""cmake_minimum_required(VERSION 3.10)
project({name} VERSION 1.0 LANGUAGES C)
if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
  set(CMAKE_BUILD_TYPE Release CACHE STRING "Build type (Release: optimised)" FORCE)
endif()
set(CMAKE_C_STANDARD 99)
set(CMAKE_C_STANDARD_REQUIRED ON)
set(CMAKE_C_EXTENSIONS OFF)
set(CMAKE_POSITION_INDEPENDENT_CODE ON)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SOURCES src/{name}_casadi.c src/{name}.c)
add_library({name} STATIC ${{SOURCES}})
add_library({name}_shared SHARED ${{SOURCES}})
set_target_properties({name}_shared PROPERTIES OUTPUT_NAME {name})
add_executable({name}_example main.c)
add_executable({name}_harness harness.c)
set_target_properties({name}_example PROPERTIES OUTPUT_NAME example)
set_target_properties({name}_harness PROPERTIES OUTPUT_NAME harness)
target_link_libraries({name}_example PRIVATE {name})
target_link_libraries({name}_harness PRIVATE {name})
foreach(target {name} {name}_shared)
  target_include_directories(${{target}} PUBLIC
    $<BUILD_INTERFACE:${{CMAKE_CURRENT_SOURCE_DIR}}/include> $<INSTALL_INTERFACE:${{CMAKE_INSTALL_INCLUDEDIR}}>)
  if(UNIX)
    target_link_libraries(${{target}} PUBLIC m)
  endif()
endforeach()
foreach(target {name} {name}_shared {name}_example {name}_harness)
  if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${{target}} PRIVATE {' '.join(WARNINGS)})
  endif()
endforeach()

install(TARGETS {name} {name}_shared EXPORT {name}Targets
        ARCHIVE DESTINATION ${{CMAKE_INSTALL_LIBDIR}}
        LIBRARY DESTINATION ${{CMAKE_INSTALL_LIBDIR}}
        RUNTIME DESTINATION ${{CMAKE_INSTALL_BINDIR}}
        INCLUDES DESTINATION ${{CMAKE_INSTALL_INCLUDEDIR}})
install(FILES include/{name}.h include/{name}_casadi.h DESTINATION ${{CMAKE_INSTALL_INCLUDEDIR}})
install(FILES README.md manifest.json DESTINATION ${{CMAKE_INSTALL_DATADIR}}/{name})
install(EXPORT {name}Targets NAMESPACE {name}:: FILE {name}Config.cmake
        DESTINATION ${{CMAKE_INSTALL_LIBDIR}}/cmake/{name})
write_basic_package_version_file(${{CMAKE_CURRENT_BINARY_DIR}}/{name}ConfigVersion.cmake
                                 COMPATIBILITY SameMajorVersion)
install(FILES ${{CMAKE_CURRENT_BINARY_DIR}}/{name}ConfigVersion.cmake
        DESTINATION ${{CMAKE_INSTALL_LIBDIR}}/cmake/{name})
"""
