# SPDX-License-Identifier: MIT
# Read by ctest after the discovered tests (TEST_INCLUDE_FILES in tests/CMakeLists.txt): the GoogleTest tests that
# take 6 s or more under the sanitizers (tools/test.sh on the 2-core machine, rounded seconds) get that as their
# COST, so that ctest -j starts them first, longest first, even without cost data from an earlier run (a fresh
# clone). Only the order depends on these numbers; a name that no longer exists is ignored. Refresh them from a
# run's output (the "Passed ... sec" column) when tests are added or their times change a lot.
set_tests_properties("EveryAlgorithm/TandemTraversalPerBuilder.MatchesBruteForce/auto" PROPERTIES COST 47)
set_tests_properties("SurveyHeuristics/EveryHeuristic.PropertiesOnGeneratedScenesOfEverySize/insertion_haber" PROPERTIES COST 15)
set_tests_properties("BnbExact.EachLevelOptimalAndNoCostlierThanEnlargesOnBundledModels" PROPERTIES COST 28)
set_tests_properties("Precision.RestingContactsFarFromTheOriginAreFound" PROPERTIES COST 26)
set_tests_properties("EveryAlgorithm/TandemTraversalPerBuilder.MatchesBruteForce/bnb_exact" PROPERTIES COST 25)
set_tests_properties("EveryAlgorithm/TandemTraversalPerBuilder.MatchesBruteForce/bnb_tightest" PROPERTIES COST 19)
set_tests_properties("BnbExact.ReturnsTheCheaperOfItsOwnTreeAndEnlarges" PROPERTIES COST 15)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/auto" PROPERTIES COST 15)
set_tests_properties("EveryAlgorithm/TandemTraversalPerBuilder.MatchesBruteForce/optimal" PROPERTIES COST 15)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/optimal" PROPERTIES COST 14)
set_tests_properties("BranchAndBoundBuilders.ValidOnBundledModels" PROPERTIES COST 13)
set_tests_properties("SurveyHeuristics.SplitSameTreeForOneAndTwoThreads" PROPERTIES COST 12)
set_tests_properties("Treelet.NeverCostlierOnBundledModels" PROPERTIES COST 12)
set_tests_properties("Scale.NoWorseThanMergeAndRatioToSplitRecorded" PROPERTIES COST 11)
set_tests_properties("Treelet.NeverCostlierOnGeneratedScenes" PROPERTIES COST 11)
set_tests_properties("BnbExact.EachLevelOptimalAndNoCostlierThanEnlargesOnGeneratedScenes" PROPERTIES COST 10)
set_tests_properties("OptimalHierarchy.NoWorseThanAnyRegisteredBuilder" PROPERTIES COST 10)
set_tests_properties("Auto.PicksBySizeAndSaysSo" PROPERTIES COST 9)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/bnb_exact" PROPERTIES COST 9)
set_tests_properties("SurveyHeuristics/EveryHeuristic.PropertiesOnGeneratedScenesOfEverySize/split" PROPERTIES COST 9)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/insertion_haber" PROPERTIES COST 8)
set_tests_properties("Registry.EachRowsFunctionIsWhatBuildRuns" PROPERTIES COST 8)
set_tests_properties("SurveyHeuristics/EveryHeuristic.PropertiesOnGeneratedScenesOfEverySize/insertion" PROPERTIES COST 8)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/bnb_tightest" PROPERTIES COST 7)
set_tests_properties("Fit.FitBestEqualsTheBestOfTheSeparateFitters" PROPERTIES COST 7)
set_tests_properties("Scale.PropertiesOnGeneratedScenes" PROPERTIES COST 7)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/bnb_enlarge" PROPERTIES COST 6)
