# The Python interpreter the package (python/) is built for; sets CLFRACTAL_PYTHON_READY.
# - pip builds (scikit-build-core sets SKBUILD): the build environment's Python, which has
#   nanobind.
# - plain CMake builds: a venv in the build tree (build/python-venv) from Debian's python3,
#   with nanobind, numpy, scipy, pytest, matplotlib (the examples), pandas and websocket-client (the report's
#   browser test over the DevTools protocol) from PyPI, installed on the first configure only;
#   the tests and benchmarks run in it.
set(CLFRACTAL_PYTHON_READY OFF)
if(SKBUILD)
  set(CLFRACTAL_PYTHON_READY ON)
  return()
endif()
set(CLFRACTAL_PYTHON_VENV ${CMAKE_BINARY_DIR}/python-venv)
set(venv_python ${CLFRACTAL_PYTHON_VENV}/bin/python)
set(venv_packages nanobind numpy scipy pytest matplotlib pandas websocket-client)
if(NOT EXISTS ${venv_python})
  find_program(CLFRACTAL_BASE_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
  find_program(CLFRACTAL_BASE_PYTHON NAMES python3)
  if(NOT CLFRACTAL_BASE_PYTHON)
    message(STATUS "python: no python3 found: the Python package is not built")
    return()
  endif()
  execute_process(COMMAND ${CLFRACTAL_BASE_PYTHON} -m venv ${CLFRACTAL_PYTHON_VENV}
    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    file(REMOVE_RECURSE ${CLFRACTAL_PYTHON_VENV})
    message(STATUS "python: '${CLFRACTAL_BASE_PYTHON} -m venv' failed (apt-get install python3-venv): "
                   "the Python package is not built\n${err}")
    return()
  endif()
endif()
execute_process(COMMAND ${venv_python} -c "import nanobind, numpy, scipy, pytest, matplotlib, pandas, websocket"
  RESULT_VARIABLE missing OUTPUT_QUIET ERROR_QUIET)
if(NOT missing EQUAL 0)
  string(REPLACE ";" " " venv_list "${venv_packages}")
  message(STATUS "python: installing ${venv_list} into ${CLFRACTAL_PYTHON_VENV} from PyPI")
  execute_process(COMMAND ${venv_python} -m pip install -q --disable-pip-version-check ${venv_packages}
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(STATUS "python: pip install ${venv_packages} failed: the Python package is not built")
    return()
  endif()
endif()
set(Python_EXECUTABLE ${venv_python})
set(CLFRACTAL_PYTHON_READY ON)
