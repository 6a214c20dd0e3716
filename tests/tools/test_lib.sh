# Shared by the command-line test scripts (sourced): a scratch folder removed on exit, the pass
# and fail counters with ok / fail, and the Debian python that has h5py and meshio.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
ok() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }
py=/usr/bin/python3
