# Finds what the Python module needs: a Python 3 interpreter that has NumPy (PYTHON_EXECUTABLE;
# the first of `python3` on PATH and /usr/bin/python3 that imports numpy, so that a python3
# earlier on PATH without Debian's python3-numpy is passed over) and pybind11 (CONFIG).
# Sets pybind11_FOUND.
if(NOT PYTHON_EXECUTABLE)
  find_program(DDEMAP_PYTHON3_ON_PATH NAMES python3)
  foreach(candidate IN ITEMS ${DDEMAP_PYTHON3_ON_PATH} /usr/bin/python3)
    if(EXISTS "${candidate}")
      execute_process(COMMAND "${candidate}" -c "import numpy" RESULT_VARIABLE numpy_missing OUTPUT_QUIET ERROR_QUIET)
      if(numpy_missing EQUAL 0)
        set(PYTHON_EXECUTABLE "${candidate}" CACHE FILEPATH "Python interpreter of the Python module and its tests (one with NumPy)")
        break()
      endif()
    endif()
  endforeach()
endif()
if(PYTHON_EXECUTABLE)
  find_package(pybind11 CONFIG QUIET)
else()
  set(pybind11_FOUND FALSE)
endif()
if(NOT pybind11_FOUND)
  message(STATUS "Python module: off (needs pybind11 and a python3 with NumPy: Debian pybind11-dev python3-dev python3-numpy)")
endif()
