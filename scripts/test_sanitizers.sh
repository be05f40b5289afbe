#!/usr/bin/env bash
# Builds the project with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan and runs the
# test suite there. Any sanitizer report fails the test that triggered it (UBSan does not recover).
# Usage: scripts/test_sanitizers.sh [extra ctest args]
set -euo pipefail
cd "$(dirname "$0")/.."

JOBS="${JOBS:-$(nproc)}"
# -g1 (line tables, no variable info) instead of RelWithDebInfo's -g: the sanitizers' stack traces keep
# their file:line, and the build takes about a third less time (identification/identification.cc: 50 s -> 33 s).
# -O1 (AddressSanitizer's documented level for usable speed) instead of -O2: the Eigen-heavy sources
# compile in a third less time (diagnosis/diagnose_select.cc: 85 s -> 59 s CPU) and nothing the
# sanitizers check depends on the level.
cmake -S . -B build-asan -DEXOTWIN_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" >/dev/null
cmake --build build-asan -j"$JOBS"

# halt_on_error: the first report ends the process with a non-zero code, so the test fails.
# detect_leaks: leaks are bugs too (LeakSanitizer).
# intercept_tls_get_addr=0: the runtime of GCC <= 13 and LLVM <= 16 takes a dynamic TLS block whose
# start lies 16 bytes past a page boundary for a pre-2.25 glibc block with a header, reads the two words
# before it as an address and a size, and LeakSanitizer's tracer then faults at exit ("Tracer caught
# signal 11", no leak reported, the test's work done): a test fails by where the heap happened to put a
# block. Without the interceptor the blocks glibc allocates for dynamic TLS are still scanned as the
# heap objects they are, reached from the thread's DTV.
export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:abort_on_error=0:strict_string_checks=1:intercept_tls_get_addr=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
# Leaks inside third-party libraries we do not build (found with this suite, nothing of ours):
#   libOSMesa.so: Mesa keeps ~0.5 kB per context made current (OSMesaMakeCurrent) after
#   OSMesaDestroyContext; render/osmesa_context.cc does destroy its context.
cat > build-asan/lsan.supp <<'SUPP'
leak:libOSMesa.so
SUPP
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PWD/build-asan/lsan.supp:print_suppressions=0}"

# Tests excluded under the sanitizers, with the reason (keep this list short):
#   install.*: they check that the installed programs hold no source path; this RelWithDebInfo build
#   carries the source file names in its debug info (and ASan's global descriptors). The installed and
#   packaged build is the Release build of scripts/test.sh, where they run.
#   the statistical sweeps below: the same code paths as shorter tests of the suite (one subject or one
#   effect: Table5Protocol.*, IdentifyCli.*, DiagnoseHiddenEffect.PairsAreFound / OffsetAndFriction...,
#   OneJointHiddenEffect.*, DiagnoseCli.*), repeated over many subjects, seeds or effects to check a
#   statistic; they were half of the suite's time under the sanitizers and find no memory error the
#   short ones miss. They run in the Release suite of scripts/test.sh.
SWEEPS="IdentificationRecovery\.FiftyRandomSubjects|IdentificationRecovery\.PaperSubjects"
SWEEPS="$SWEEPS|IdentificationSensitivity\.TableOfErrorGrowth|Excitation\.GainInRecoveryError"
SWEEPS="$SWEEPS|DiagnoseHiddenEffect\.EverySingleEffectIsNamedMeasuredAndRemoved|DiagnoseHiddenEffect\.NoEffectNamedOnCleanData"
#   The motion fit's hidden-effect cases beyond one: the strap, the delay, the pair and the hip dead bands
#   (60 s records) drive the same rollouts, Jacobian threads, selection and dead-band probes as
#   HiddenKneeBacklashIsNamed and NothingIsNamedOnTheRigidPlant, which stay (each case ~25 s in Release
#   at load 10).
SWEEPS="$SWEEPS|MotionFit\.HiddenKneeStrapWithAHumanIsNamed|MotionFit\.HiddenKneeSensorDelayIsNamed"
SWEEPS="$SWEEPS|MotionFit\.KneeBacklashAndCoulombFrictionAreBothNamed|MotionFit\.HiddenHipBacklashOf30MilliradIsNamedWhereverTheWindowsRestart"
SWEEPS="$SWEEPS|MotionFit\.HiddenHipBacklashOf20MilliradIsNamedAlone|MotionFit\.HiddenKneeBacklashOf5MilliradIsSizedWithTheExtendedTwinsWeights"
#   The strap of Table 5's human side named from the true twin: a table5 subject run (the other
#   Table5Protocol tests keep that path) and a motion fit (MotionFit's keep it).
SWEEPS="$SWEEPS|Table5Protocol\.TheHumanSidesStrapIsNamedInTheGaitWithTheTrueAndTheIdentifiedTwin"
#   The motion fits of real-rig records (each alone, and six together; the same paths on real data).
SWEEPS="$SWEEPS|DiagnoseRealRig\.MotionFitOfEachRecordAloneIsNeverWorseThanTheTorqueFitsTwinAndItsCoulombIsStable"
SWEEPS="$SWEEPS|DiagnoseRealRig\.MotionFitOfSixRecordsKeepsTheRotorInertiaTheSeventhNeeds"
SWEEPS="$SWEEPS|DiagnoseRealRig\.MotionFitReplaysTheRecordsLeftOutAtLeastAsWellAsTheTorqueFit"
#   Further sweeps and repeats, each over 8 s in the Release suite (30-90 s here): cli.regress_suite_test
#   (the 20 shipped scenarios through `regress`; each scenario's runner runs in the runner, app and cli
#   tests), DiagnoseHiddenEffect.PairsAreFound and .OffsetAndFrictionTogetherAreBothNamed (pairs of the
#   single-effect path MotionFit / OneJointHiddenEffect / DiagnoseCli keep), OneJointHiddenEffect.Every
#   SingleEffectIsNamedAtItsValue (every effect; NothingIsNamedOnCleanRecords keeps the path),
#   HalRunner.ViscousSweepTroughOverOperators (a sweep over operators of the HAL runs the other HalRunner
#   tests run), Excitation.DesignImprovesCriterionWithinLimits (the optimizer's loop; the other
#   Excitation and HarmonicTrajectory tests keep it), PlantScenario.EffectsCarriedByTheForwardPlantAreNamed
#   (a run + diagnose: PlantScenario.KneeFrictionInThePlantIsWhatDiagnoseNames keeps it), DiagnoseOther
#   Chain.FindsEffectsOnAChainThatIsNotTheLeg (diagnose's path on another chain's model; DiagnoseCli keeps it). Together ~150 s of the Release
#   suite, ~4 min of this one's wall time.
SWEEPS="$SWEEPS|cli\.regress_suite_test|DiagnoseHiddenEffect\.PairsAreFound|DiagnoseHiddenEffect\.OffsetAndFrictionTogetherAreBothNamed"
SWEEPS="$SWEEPS|OneJointHiddenEffect\.EverySingleEffectIsNamedAtItsValue|HalRunner\.ViscousSweepTroughOverOperators"
SWEEPS="$SWEEPS|Excitation\.DesignImprovesCriterionWithinLimits|PlantScenario\.EffectsCarriedByTheForwardPlantAreNamed"
SWEEPS="$SWEEPS|DiagnoseOtherChain\.FindsEffectsOnAChainThatIsNotTheLeg"
SWEEPS="$SWEEPS|DiagnoseCompleteness\.CleanRecordsAreComplete|DiagnoseCompleteness\.OffTableFormsAreIncomplete"
SWEEPS="$SWEEPS|DiagnoseCompleteness\.MotionFitAssessesItsTwin|TermSearch\.CleanRecordsNameNoTerm|TermSearch\.FormsBesideATableEffectAreBothNamed"
#   Issue 64's drawn combinations (a 20 s run and a motion fit each, ~18 s in Release): the motion
#   fit's rounds and exchanges that MotionFit.HiddenKneeBacklashIsNamed keeps (the elimination on the
#   plant's loop over two effects aside); the draw itself (MotionRounds.CombinationsAreDrawnFromTheIssuesRanges) stays.
SWEEPS="$SWEEPS|MotionRounds\.DrawnCombination[0-9]+IsNamedAndNothingElse"
EXCLUDE="^install\.|^($SWEEPS)\$"
# The command-line mutation fuzz (tests/cli/fuzz_cli_test.sh): a third of the Release suite's 330
# mutations here (the same seed), ~30 s -> ~10 s of this suite's CPU.
export FUZZ_CLI_COUNT="${FUZZ_CLI_COUNT:-110}"
start=$(date +%s)
ctest --test-dir build-asan --output-on-failure -j"$JOBS" ${EXCLUDE:+-E "$EXCLUDE"} "$@"
echo "test_sanitizers: suite took $(( $(date +%s) - start )) s under ASan+UBSan"
