#!/usr/bin/env bash
# Placeholder: checks of the udev rules arrive with the drivers issue. Usage: check_rules.sh UDEV_DIR
echo "0 passed, 0 failed"
