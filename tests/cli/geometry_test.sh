#!/usr/bin/env bash
# Placeholder: being written. Usage: geometry_test.sh DAQ_BINARY DATA_DIR
echo "0 passed, 0 failed"
