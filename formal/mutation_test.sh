#!/usr/bin/env bash
# The formal proofs can fail, with both engines: copies of the RTL with one handshake broken must
# make the proofs fail.
#  - smtbmc: the mutant measurement_uart advances the frame's byte index on every clock instead
#    of on the transmitter's ready (`else if (byte_ready)` -> `else`), so the byte offered to
#    uart_tx changes while it waits: the AXI-Stream rule asserted of uart_tx's input fails (BMC
#    finds it in a few steps).
#  - abc: the mutant peak_detector leaves S_OUT without m_ready (drops a waiting event): the
#    output-stream assertion (m_valid held until m_ready) fails in BMC.
#  - abc: the mutant bandpass_sos (shared) runs its schedule while an output waits
#    (`run = !park`): the next sample overwrites m_data, the output-stream assertion fails.
# Exit 0 when all three mutants are caught, 1 when one slips through, 2 on a tool error.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
case "${1:-}" in -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
work=$(mktemp -d "${TMPDIR:-/tmp}/ranging-mutant-XXXXXX")
trap 'rm -rf "$work"' EXIT
cp "$root"/rtl/*.v "$work/"
sed -i 's/end else if (byte_ready) begin/end else begin/' "$work/measurement_uart.v"
if cmp -s "$root/rtl/measurement_uart.v" "$work/measurement_uart.v"; then
  echo "mutation_test: the mutation did not apply (rtl/measurement_uart.v changed?)" >&2; exit 2
fi
"$root/formal/run_formal.sh" measurement_uart --rtl "$work" --out "$work/out" --depth 20 --bmc-only
rc=$?
[[ $rc == 2 ]] && { echo "mutation_test: tool error" >&2; exit 2; }
if [[ $rc == 1 ]] && grep -q "uart_tx.v" "$work/out/measurement_uart-bmc.log"; then
  echo "mutation_test: the broken handshake is caught ($(grep -o 'Assert failed in [^ ]* [^ ]*' "$work/out/measurement_uart-bmc.log" | head -1))"
else
  echo "mutation_test: the measurement_uart mutant was NOT caught (run_formal exit $rc)" >&2
  exit 1
fi
# the abc engine: the detector's event is dropped while it waits for m_ready
cp "$root/rtl/peak_detector.v" "$work/peak_detector.v"
sed -i 's/S_OUT: if (m_ready) state <= S_IDLE;/S_OUT: state <= S_IDLE;/' "$work/peak_detector.v"
if cmp -s "$root/rtl/peak_detector.v" "$work/peak_detector.v"; then
  echo "mutation_test: the mutation did not apply (rtl/peak_detector.v changed?)" >&2; exit 2
fi
# an assertion cell is named after the line before the assert (its enclosing `if`, or the
# previous assert)
held=$(grep -n 'assert(m_valid);' "$work/peak_detector.v" | head -1 | cut -d: -f1)
msg=$("$root/formal/run_formal.sh" peak_detector --rtl "$work" --out "$work/out-pd" --bmc-only)
rc=$?
[[ $rc == 2 ]] && { echo "mutation_test: tool error" >&2; exit 2; }
if [[ $rc == 1 ]] && grep -q "peak_detector.v:$((held - 1))\\$" <<<"$msg"; then
  echo "mutation_test: the dropped event is caught ($msg)"
else
  echo "mutation_test: the peak_detector mutant was NOT caught as expected (run_formal exit $rc: $msg)" >&2
  exit 1
fi
# the filter's schedule no longer freezes while its output waits for m_ready
cp "$root/rtl/bandpass_sos.v" "$work/bandpass_sos.v"
sed -i 's/  wire                  run = !(out_valid \&\& !m_ready) \&\& !park;/  wire                  run = !park;/' "$work/bandpass_sos.v"
if cmp -s "$root/rtl/bandpass_sos.v" "$work/bandpass_sos.v"; then
  echo "mutation_test: the mutation did not apply (rtl/bandpass_sos.v changed?)" >&2; exit 2
fi
stable=$(grep -n 'assert(m_data == $past(m_data)' "$work/bandpass_sos.v" | head -1 | cut -d: -f1)
msg=$("$root/formal/run_formal.sh" bandpass_sos --rtl "$work" --out "$work/out-bp" --bmc-only)
rc=$?
[[ $rc == 2 ]] && { echo "mutation_test: tool error" >&2; exit 2; }
if [[ $rc == 1 ]] && grep -q "bandpass_sos.v:$((stable - 1))\\$" <<<"$msg"; then
  echo "mutation_test: the overwritten output is caught ($msg)"
  exit 0
fi
echo "mutation_test: the bandpass_sos mutant was NOT caught as expected (run_formal exit $rc: $msg)" >&2
exit 1
