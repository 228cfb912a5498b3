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
#  - abc: the mutant tof_distance leaves OUT without m_ready: m_valid held fails.
#  - abc: the mutant sound_speed_cal drops the rounding term floor(ToF / 2) from its numerator:
#    the division's invariant against the equation fails.
#  - abc, the system proof: the mutant ranging_system puts the ADC's sticky overrun flag straight
#    into the frame's flags byte: measurement_uart's input rule (fields stable while waiting),
#    asserted of its driver in the composition, fails.
# Exit 0 when all six mutants are caught, 1 when one slips through, 2 on a tool error.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
case "${1:-}" in -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
work=$(mktemp -d "${TMPDIR:-/tmp}/ranging-mutant-XXXXXX")
trap 'rm -rf "$work"' EXIT
cp "$root"/rtl/*.v "$work/"
# mutate FILE SED: apply one edit to the copy of rtl/FILE (exit 2 if it no longer applies)
mutate() {
  sed -i "$2" "$work/$1"
  if cmp -s "$root/rtl/$1" "$work/$1"; then
    echo "mutation_test: the mutation did not apply (rtl/$1 changed?)" >&2; exit 2
  fi
}
# caught_at JOB FILE LINE WHAT: the abc job must fail on the assertion cell of LINE of FILE. A
# cell is named after the line before its assert (its enclosing `if`, or the previous assert).
caught_at() {
  local msg rc
  msg=$("$root/formal/run_formal.sh" "$1" --rtl "$work" --out "$work/out-$1" --bmc-only)
  rc=$?
  [[ $rc == 2 ]] && { echo "mutation_test: tool error" >&2; exit 2; }
  if [[ $rc == 1 ]] && grep -q "$2:$(( $3 - 1 ))\\$" <<<"$msg"; then
    echo "mutation_test: $4 is caught ($msg)"
  else
    echo "mutation_test: the $1 mutant was NOT caught as expected (run_formal exit $rc: $msg)" >&2
    exit 1
  fi
}
line_of() { grep -nF "$2" "$work/$1" | head -1 | cut -d: -f1; }

mutate measurement_uart.v 's/end else if (byte_ready) begin/end else begin/'
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
mutate peak_detector.v 's/S_OUT: if (m_ready) state <= S_IDLE;/S_OUT: state <= S_IDLE;/'
caught_at peak_detector peak_detector.v "$(line_of peak_detector.v 'assert(m_valid);')" "the dropped event"
# the filter's schedule no longer freezes while its output waits for m_ready
mutate bandpass_sos.v 's/  wire                  run = !(out_valid \&\& !m_ready) \&\& !park;/  wire                  run = !park;/'
caught_at bandpass_sos bandpass_sos.v "$(line_of bandpass_sos.v 'assert(m_data == $past(m_data)')" "the overwritten output"
# the measurement leaves before the UART took it
mutate tof_distance.v 's/        OUT: if (m_ready) state <= IDLE;/        OUT: state <= IDLE;/'
caught_at tof_distance tof_distance.v "$(line_of tof_distance.v 'assert(m_valid);')" "the dropped measurement"
# C without its rounding term
mutate sound_speed_cal.v 's/        num <= D_SHIFTED + (meas_tof >> 1);/        num <= D_SHIFTED;/'
caught_at sound_speed_cal sound_speed_cal.v "$(line_of sound_speed_cal.v 'assert((num >> cnt)')" "the unrounded C"
# the system: the ADC's sticky overrun flag straight into the frame's flags (it may rise while a
# measurement waits for the UART): measurement_uart's input rule, asserted of its driver, fails
# (the other mutants undone first: the system job reads tof_distance.v and measurement_uart.v)
cp "$root"/rtl/*.v "$work/"
mutate ranging_system.v "s/    .s_flags({5'd0, frame_error, m_flags}),/    .s_flags({5'd0, led_error, m_flags}),/"
caught_at ranging_system measurement_uart.v "$(line_of measurement_uart.v 'assume({s_code, s_flags')" \
  "the overrun flag changing under a waiting measurement"
exit 0
