#!/usr/bin/env python3
"""ctest code_size.diagnosis: scripts/check_code_size.py (issue 62: in diagnosis/ no file over 1000 lines,
no function over 200)
 - on tests/code_size/fixture: fails, naming exactly TooLong (201 lines) and not JustRight (200, a
   template line included), and names the file when the file limit is below its length;
 - on diagnosis/: passes.
Args: the source tree.
"""
import subprocess
import sys

src = sys.argv[1]
check = [sys.executable, src + '/scripts/check_code_size.py']
fixture = src + '/tests/code_size/fixture'


def run(*args):
    p = subprocess.run(check + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


rc, out = run(fixture)
if rc == 0:
    sys.exit('the check passed a fixture with a function of 201 lines:\n' + out)
named = [line for line in out.splitlines() if ': function ' in line]
if named != [f'{fixture}/long_function.cc:13: function TooLong has 201 lines, limit 200']:
    sys.exit('expected the check to name TooLong (201 lines at line 13) alone:\n' + out)
rc, out = run('--max-file-lines', '415', '--max-function-lines', '201', fixture)
if rc == 0 or out.strip() != f'{fixture}/long_function.cc:1: file has 416 lines, limit 415':
    sys.exit('expected the check to name the fixture file alone (416 lines, limit 415):\n' + out)
rc, out = run(src + '/diagnosis')
if rc != 0:
    sys.exit('diagnosis/ exceeds the size limits:\n' + out)
print(out.strip())
print('code size: fixture refused (TooLong named), diagnosis/ accepted')
