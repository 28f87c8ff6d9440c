#!/usr/bin/env bash
# Build the Pinocchio reference benchmark against the Pinocchio of a Python venv (PyPI's pin, with
# cmeel-eigen and cmeel-urdfdom-headers for the headers):  build.sh VENV OUT
# The defines are Pinocchio's own (its CMake config); no -march=native: the library is built for
# generic x86-64, and Eigen's alignment must match it.
set -euo pipefail
P="$(ls -d "$1"/lib/python3*/site-packages/cmeel.prefix | head -1)"
g++ -O3 -DNDEBUG -std=c++17 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 \
  -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -DBOOST_FUSION_INVOKE_FUNCTION_OBJECT_MAX_ARITY=12 -DPINOCCHIO_WITH_URDFDOM \
  "$(dirname "$0")/pinocchio_step.cpp" -I"$P/include" -I"$P/include/eigen3" -I"$P/include/urdfdom_headers" -I"$P/include/urdfdom" \
  -L"$P/lib" -lpinocchio_default -lpinocchio_parsers -lurdfdom_model -Wl,-rpath,"$P/lib" -o "$2"
