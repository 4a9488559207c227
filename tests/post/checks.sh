#!/bin/bash
# The counters and checks the post-processing test scripts share; sourced by tests/post/test_*.sh.
#   check NAME COMMAND...  pass when COMMAND exits 0, else fail and show its first 20 lines;
#   pass NAME / fail NAME  count a check by hand;
#   png_ok FILE...         each file is a PNG at least 200 px wide and high with more than 20
#                          colours (not blank); needs $py (/usr/bin/python3 with matplotlib);
#   finish                 print the counts; its status is 0 only when nothing failed.
passed=0
failed=0
pass() {
  echo "ok   $1"
  passed=$((passed + 1))
}
fail() {
  echo "FAIL $1"
  failed=$((failed + 1))
}
check() {
  local name=$1 out
  shift
  if out=$("$@" 2>&1); then pass "$name"; else
    fail "$name"
    sed -n '1,20p' <<<"$out"
  fi
}
png_ok() {
  "$py" - "$@" <<'PY'
import sys
import matplotlib.image as mpimg
import numpy as np
for path in sys.argv[1:]:
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    img = mpimg.imread(path)
    assert img.shape[0] >= 200 and img.shape[1] >= 200, f"{path}: {img.shape}"
    colours = np.unique((img[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 20, f"{path}: only {len(colours)} colours"
PY
}
finish() {
  echo "$passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
