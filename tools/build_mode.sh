# Sourced by setup.sh and run_tests.sh: SNEDE_NATIVE=ON (default) compiles for this processor
# (-march=native), OFF for the x86-64 baseline (what another machine runs; CI runs both).
# Each mode has its own build directories (suffix "" or "-portable").
SNEDE_NATIVE=${SNEDE_NATIVE:-ON}
case "$SNEDE_NATIVE" in
  ON) BUILD_SUFFIX="" ;;
  OFF) BUILD_SUFFIX="-portable" ;;
  *) echo "SNEDE_NATIVE must be ON or OFF, got '$SNEDE_NATIVE'" >&2; exit 2 ;;
esac
export SNEDE_NATIVE
