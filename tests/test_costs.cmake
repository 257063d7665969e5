# SPDX-License-Identifier: MIT
# Read by ctest after the discovered tests (TEST_INCLUDE_FILES in tests/CMakeLists.txt): the GoogleTest tests that
# take 4 s or more under the sanitizers (tools/test.sh on the 2-core machine, rounded seconds) get that as their
# COST, so that ctest -j starts them first, longest first, even without cost data from an earlier run (a fresh
# clone). Only the order depends on these numbers; a name that no longer exists is ignored. Refresh them from a
# run's output (the "Passed ... sec" column) when tests are added or their times change a lot.
set_tests_properties("Precision.RestingContactsFarFromTheOriginAreFound" PROPERTIES COST 11)
set_tests_properties("EveryAlgorithm/TandemTraversalPerBuilder.MatchesBruteForce/auto" PROPERTIES COST 9)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/auto" PROPERTIES COST 8)
set_tests_properties("SurveyHeuristics/EveryHeuristic.PropertiesOnGeneratedScenesOfEverySize/insertion_haber" PROPERTIES COST 8)
set_tests_properties("BnbExact.ReturnsTheCheaperOfItsOwnTreeAndEnlarges" PROPERTIES COST 7)
set_tests_properties("Treelet.SharedFitCacheChangesNoTree" PROPERTIES COST 7)
set_tests_properties("BranchAndBoundBuilders.ValidOnBundledModels" PROPERTIES COST 7)
set_tests_properties("Scale.NoWorseThanMergeAndRatioToSplitRecorded" PROPERTIES COST 6)
set_tests_properties("Binned.PropertiesOnGeneratedScenesEveryPolicy" PROPERTIES COST 6)
set_tests_properties("EveryAlgorithm/TandemTraversalPerBuilder.MatchesBruteForce/optimal" PROPERTIES COST 6)
set_tests_properties("Objective.EachOptimumIsCheapestUnderItsOwnObjectiveAndTheyDiffer" PROPERTIES COST 6)
set_tests_properties("SurveyHeuristics.SplitSameTreeForOneAndTwoThreads" PROPERTIES COST 6)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/bnb_exact" PROPERTIES COST 6)
set_tests_properties("BnbExact.EachLevelOptimalAndNoCostlierThanEnlargesOnGeneratedScenes" PROPERTIES COST 5)
set_tests_properties("EveryAlgorithm/PrecisionPerBuilder.RigidMotionsKeepThePairsUpToTheBand/optimal" PROPERTIES COST 5)
set_tests_properties("Treelet.NeverCostlierOnGeneratedScenes" PROPERTIES COST 5)
set_tests_properties("Auto.RefinesTheTwoCheapestMembersAboveThirtyTwoPrimitives" PROPERTIES COST 5)
set_tests_properties("Treelet.NeverCostlierOnBundledModels" PROPERTIES COST 5)
set_tests_properties("Binned.CoincidentAndFlatScenes" PROPERTIES COST 4)
