#!/bin/bash
# run_with_stacks.sh SECONDS DIR COMMAND: runs the bash command line COMMAND and exits with its
# status. Past SECONDS, as timeout(1) does, it kills the command and exits 124, but first
# writes every thread's stack of each hiveslam process under it to DIR/stacks.log (with gdb,
# where installed): a node that hangs once in a hundred runs says where.
limit=$1 dir=$2
bash -c "$3" &
pid=$!
below() { local p; for p in $(pgrep -P "$1"); do echo "$p"; below "$p"; done; }
for ((tick = 0; tick < limit * 10; ++tick)); do
  if ! kill -0 "$pid" 2>/dev/null; then
    wait "$pid"
    exit $?
  fi
  sleep 0.1
done
procs=$(below "$pid")
if command -v gdb > /dev/null; then
  for p in $procs; do
    [ "$(cat /proc/"$p"/comm 2>/dev/null)" = hiveslam ] || continue
    echo "=== $(tr '\0' ' ' < /proc/"$p"/cmdline)"
    # The binary by its /proc link: symbols resolve though it was rebuilt meanwhile.
    timeout 60 gdb /proc/"$p"/exe -p "$p" -batch -ex 'thread apply all bt' 2>&1 | grep -E '^(Thread|#)'
  done > "$dir/stacks.log"
fi
kill -KILL $procs "$pid" 2>/dev/null
wait "$pid"
exit 124
