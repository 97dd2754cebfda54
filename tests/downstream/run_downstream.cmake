# SPDX-License-Identifier: GPL-3.0-or-later
#
# Installs a pcl_ms build tree into a scratch prefix, then configures, builds
# and runs the consumer project in this folder against that prefix with
# find_package(pcl_ms). Fails on the first step that fails.
#
#   cmake -DPCL_MS_BINARY_DIR=<build> -DPCL_MS_SOURCE_DIR=<source>
#         [-DPCL_MS_CONFIG=Release] [-DPCL_MS_GENERATOR=<generator>]
#         [-DPCL_MS_C_COMPILER=<cc>] [-DPCL_MS_CXX_COMPILER=<c++>]
#         -P tests/downstream/run_downstream.cmake
#
# Everything goes to <build>/downstream_test/ (prefix/ and build/), which is
# wiped at the start of each run.
cmake_minimum_required(VERSION 3.16)

foreach(_required PCL_MS_BINARY_DIR PCL_MS_SOURCE_DIR)
  if(NOT DEFINED ${_required} OR "${${_required}}" STREQUAL "")
    message(FATAL_ERROR "run_downstream.cmake: -D${_required}=... is required")
  endif()
endforeach()
if(NOT DEFINED PCL_MS_CONFIG OR "${PCL_MS_CONFIG}" STREQUAL "")
  set(PCL_MS_CONFIG Release)
endif()

set(_work "${PCL_MS_BINARY_DIR}/downstream_test")
set(_prefix "${_work}/prefix")
set(_build "${_work}/build")
set(_consumer_source "${PCL_MS_SOURCE_DIR}/tests/downstream")

# Runs one step, echoing its command; stops the script if it fails.
function(_run_step description)
  string(REPLACE ";" " " _shown "${ARGN}")
  message(STATUS "[downstream] ${description}: ${_shown}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "[downstream] ${description} failed (${_rc})")
  endif()
endfunction()

file(REMOVE_RECURSE "${_work}")
file(MAKE_DIRECTORY "${_work}")

# 1. Install the build tree.
_run_step("install"
  "${CMAKE_COMMAND}" --install "${PCL_MS_BINARY_DIR}" --prefix "${_prefix}" --config "${PCL_MS_CONFIG}")

file(GLOB_RECURSE _config_files "${_prefix}/*/pcl_msConfig.cmake")
if(NOT _config_files)
  message(FATAL_ERROR "[downstream] no pcl_msConfig.cmake was installed under ${_prefix}")
endif()
foreach(_file include/pcl_ms/medial_scaffold_reconstruction.h
              include/pcl_ms/impl/medial_scaffold_reconstruction.hpp)
  if(NOT EXISTS "${_prefix}/${_file}")
    message(FATAL_ERROR "[downstream] ${_file} was not installed")
  endif()
endforeach()

# 2. Configure the consumer against the prefix only.
set(_configure_args
  -S "${_consumer_source}" -B "${_build}"
  "-DCMAKE_BUILD_TYPE=${PCL_MS_CONFIG}"
  "-DCMAKE_PREFIX_PATH=${_prefix}"
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
if(DEFINED PCL_MS_GENERATOR AND NOT "${PCL_MS_GENERATOR}" STREQUAL "")
  list(APPEND _configure_args -G "${PCL_MS_GENERATOR}")
endif()
if(DEFINED PCL_MS_C_COMPILER AND NOT "${PCL_MS_C_COMPILER}" STREQUAL "")
  list(APPEND _configure_args "-DCMAKE_C_COMPILER=${PCL_MS_C_COMPILER}")
endif()
if(DEFINED PCL_MS_CXX_COMPILER AND NOT "${PCL_MS_CXX_COMPILER}" STREQUAL "")
  list(APPEND _configure_args "-DCMAKE_CXX_COMPILER=${PCL_MS_CXX_COMPILER}")
endif()
_run_step("configure" "${CMAKE_COMMAND}" ${_configure_args})

# The package must come from the scratch prefix, not from the build tree or
# a system copy.
file(STRINGS "${_build}/CMakeCache.txt" _dir_line REGEX "^pcl_ms_DIR:")
string(REGEX REPLACE "^pcl_ms_DIR:[A-Z]*=" "" _found_dir "${_dir_line}")
get_filename_component(_prefix_real "${_prefix}" REALPATH)
get_filename_component(_found_real "${_found_dir}" REALPATH)
string(FIND "${_found_real}/" "${_prefix_real}/" _at)
if(NOT _at EQUAL 0)
  message(FATAL_ERROR "[downstream] pcl_ms was found in ${_found_dir}, not under ${_prefix}")
endif()

# 3. Build it.
_run_step("build" "${CMAKE_COMMAND}" --build "${_build}" --config "${PCL_MS_CONFIG}")

# 4. Run it.
set(_exe "${_build}/pcl_ms_downstream")
if(NOT EXISTS "${_exe}" AND EXISTS "${_build}/${PCL_MS_CONFIG}/pcl_ms_downstream")
  set(_exe "${_build}/${PCL_MS_CONFIG}/pcl_ms_downstream")
endif()
_run_step("run" "${_exe}")

message(STATUS "[downstream] passed")
