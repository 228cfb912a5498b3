#!/usr/bin/env bash
# The formal proofs can fail: a copy of the RTL with one handshake broken must make the proof of
# measurement_uart fail. The mutant advances the frame's byte index on every clock instead of on
# the transmitter's ready (`else if (byte_ready)` -> `else`), so the byte offered to uart_tx
# changes while it waits: the AXI-Stream rule asserted of uart_tx's input fails (BMC finds it in
# a few steps). Exit 0 when the mutant is caught, 1 when it slips through, 2 on a tool error.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
case "${1:-}" in -h|--help) sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
work=$(mktemp -d "${TMPDIR:-/tmp}/ranging-mutant-XXXXXX")
trap 'rm -rf "$work"' EXIT
cp "$root"/rtl/*.v "$work/"
sed -i 's/end else if (byte_ready) begin/end else begin/' "$work/measurement_uart.v"
if cmp -s "$root/rtl/measurement_uart.v" "$work/measurement_uart.v"; then
  echo "mutation_test: the mutation did not apply (rtl/measurement_uart.v changed?)" >&2; exit 2
fi
"$root/formal/run_formal.sh" measurement_uart --rtl "$work" --out "$work/out" --depth 20 --bmc-only
rc=$?
if [[ $rc == 1 ]] && grep -q "uart_tx.v" "$work/out/measurement_uart-bmc.log"; then
  echo "mutation_test: the broken handshake is caught ($(grep -o 'Assert failed in [^ ]* [^ ]*' "$work/out/measurement_uart-bmc.log" | head -1))"
  exit 0
fi
[[ $rc == 2 ]] && { echo "mutation_test: tool error" >&2; exit 2; }
echo "mutation_test: the mutant was NOT caught (run_formal exit $rc)" >&2
exit 1
