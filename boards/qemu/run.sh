#!/usr/bin/env bash
# Runs a QEMU image of this package and decodes its defmt log. It is the
# runner of `cargo run` in this directory (see .cargo/config.toml) and works
# on its own too:
#
#     qemu/run.sh target/thumbv6m-none-eabi/release/qemu
#
# Needs qemu-system-arm and defmt-print (`cargo install defmt-print`). The exit
# status is the firmware's (semihosting exit: 0 = every check passed).
#
# `-icount shift=0,sleep=off`: one instruction is one nanosecond of virtual
# time and idle time is skipped, so a run and its log repeat exactly.
set -euo pipefail

elf="${1:?usage: run.sh <ELF of a QEMU image>}"

# QEMU 7.2 prints "Timer with period zero, disabling" at every start of this
# machine, before the firmware runs: its model of the board's watchdog starts
# at reset while the system clock still reads 0 Hz. The watchdog then stays
# stopped (the firmware never loads it), so the line is dropped from stderr.
qemu-system-arm -machine lm3s6965evb -cpu cortex-m0 -nographic \
    -semihosting-config enable=on,target=native \
    -icount shift=0,sleep=off \
    -kernel "$elf" \
    2> >(grep -vxF 'Timer with period zero, disabling' >&2) |
    defmt-print -e "$elf"
