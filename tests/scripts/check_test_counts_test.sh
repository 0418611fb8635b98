#!/bin/sh
# Tests scripts/check-test-counts.py, the guard that fails scripts/test.sh's sanitizer stage when
# it ran no test or fewer than the first stage: it must pass when every non-CUDA test that passed
# first passed again, and fail (naming the tests) when one is missing or skipped, or none ran.
# Usage: check_test_counts_test.sh SOURCE_DIR WORK_DIR
set -u
check="$1/scripts/check-test-counts.py"
work="$2"
mkdir -p "$work"
[ -x /usr/bin/python3 ] || { echo "skipped: no /usr/bin/python3"; exit 77; }
case_xml() {  # case_xml FILE "name status" ...
  file=$1
  shift
  {
    echo '<?xml version="1.0" encoding="UTF-8"?><testsuite name="(empty)">'
    for t in "$@"; do
      set -- $t
      echo "<testcase name=\"$1\" classname=\"$1\" time=\"0.1\" status=\"$2\"></testcase>"
    done
    echo '</testsuite>'
  } >"$work/$file"
}
case_xml first.xml "Grid.Sort run" "Param/Case.Run/vulkan_0__#_GetParam()_=_0x55d0 run" \
  "Conformance/Grid.Sort/cuda_0 run" "Cli.RunOnCuda notrun" "Render.Png notrun" "Python.Module run"
case_xml same.xml "Grid.Sort run" "Param/Case.Run/vulkan_0__#_GetParam()_=_0x7f10 run" \
  "Sanitizers.LeakCanary run"
case_xml missing.xml "Param/Case.Run/vulkan_0 run"
case_xml skipped.xml "Grid.Sort notrun" "Param/Case.Run/vulkan_0 run"
case_xml failed.xml "Grid.Sort fail" "Param/Case.Run/vulkan_0 run"
case_xml none.xml
# GoogleTest's "  # GetParam() = ..." suffix: spaces are written as '_' above so that the word
# splitting of case_xml keeps them together; put them back.
sed -i 's/__#_GetParam()_=_/  # GetParam() = /' "$work"/*.xml

fails=0
expect() {  # expect RC FILE
  /usr/bin/python3 "$check" "$work/first.xml" "$work/$2" >"$work/out.txt" 2>&1
  rc=$?
  if { [ "$1" = 0 ] && [ $rc -ne 0 ]; } || { [ "$1" != 0 ] && [ $rc -eq 0 ]; }; then
    echo "FAIL: $2: exit code $rc, expected $( [ "$1" = 0 ] && echo 0 || echo non-zero)"
    cat "$work/out.txt"
    fails=$((fails + 1))
  else
    echo "ok: $2 (exit $rc): $(tail -n 1 "$work/out.txt")"
  fi
}
expect 0 same.xml
expect 1 missing.xml
expect 1 skipped.xml
expect 1 failed.xml
expect 1 none.xml
[ $fails -eq 0 ]
