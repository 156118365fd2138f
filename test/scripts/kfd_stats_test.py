"""kfd_stats (kfd-compare's statistics) against values computed by hand."""
import itertools
import math
import random
import unittest

from kfd_tools import stats as st


class Summaries(unittest.TestCase):
    def test_quantiles_interpolate_linearly_like_numpy(self):
        s = st.summary([4, 1, 3, 2])
        self.assertEqual((s["n"], s["median"], s["q1"], s["q3"]), (4, 2.5, 1.75, 3.25))
        self.assertAlmostEqual(s["mean"], 2.5)
        self.assertAlmostEqual(s["std"], math.sqrt(5.0 / 3.0))  # sample std, n - 1

    def test_missing_values_are_left_out_and_nothing_is_nan(self):
        self.assertEqual(st.summary([None, 2.0, float("nan")])["n"], 1)
        self.assertTrue(math.isnan(st.summary([])["median"]))


class SignTest(unittest.TestCase):
    def test_seventeen_of_twenty(self):
        # 2 * (C(20,0) + C(20,1) + C(20,2) + C(20,3)) / 2^20 = 2 * 1351 / 1048576
        self.assertAlmostEqual(st.sign_test(17, 3), 2 * 1351 / 2 ** 20, places=12)
        self.assertAlmostEqual(st.sign_test(3, 17), 2 * 1351 / 2 ** 20, places=12)

    def test_twelve_of_twenty_is_no_evidence(self):
        # sum of C(20, 0..8) = 263950
        self.assertAlmostEqual(st.sign_test(12, 8), 2 * 263950 / 2 ** 20, places=12)

    def test_balanced_and_empty_give_one(self):
        self.assertEqual(st.sign_test(10, 10), 1.0)
        self.assertEqual(st.sign_test(0, 0), 1.0)

    def test_ties_are_counted_apart(self):
        self.assertEqual(st.wins_losses_ties([1, 2, 3, 4], [2, 2, 1, 4]), (1, 1, 2))


class SmallestP(unittest.TestCase):
    def test_one_sign_for_every_pair_is_the_best_either_test_can_do(self):
        # 2 / 2^n: n = 5 cannot reach 0.05 (2/32), n = 6 can (2/64)
        self.assertAlmostEqual(st.smallest_p(5), 2 / 32)
        self.assertAlmostEqual(st.smallest_p(6), 2 / 64)
        self.assertGreaterEqual(st.smallest_p(5), 0.05)
        self.assertLess(st.smallest_p(6), 0.05)
        self.assertEqual(st.smallest_p(0), 1.0)


class Wilcoxon(unittest.TestCase):
    def test_all_positive_differences(self):
        # n = 5, W+ = 15: only 1 of 32 sign patterns reaches it; two-sided 2/32
        w, n, p = st.wilcoxon([2, 3, 4, 5, 6], [1, 1, 1, 1, 1])
        self.assertEqual((w, n), (15, 5))
        self.assertAlmostEqual(p, 2 / 32)

    def test_mixed_signs_without_ties(self):
        # d = -1, 2, 3, -4, 5: W+ = 10; subsets of {1..5} summing to >= 10: 10 of 32
        w, n, p = st.wilcoxon([0, 2, 3, 0, 5], [1, 0, 0, 4, 0])
        self.assertEqual((w, n), (10, 5))
        self.assertAlmostEqual(p, 2 * 10 / 32)

    def test_ties_get_average_ranks_and_zeros_are_dropped(self):
        # d = 1, -2, 2, 3, 0 -> zero dropped; |d| ranks 1, 2.5, 2.5, 4; W+ = 1 + 2.5 + 4 = 7.5;
        # of the 16 sign patterns, 4 have W+ >= 7.5 (7.5, 7.5, 9, 10): p = 2 * 4/16
        w, n, p = st.wilcoxon([1, 0, 2, 3, 5], [0, 2, 0, 0, 5])
        self.assertEqual((w, n), (7.5, 4))
        self.assertAlmostEqual(p, 0.5)

    def test_no_difference_left(self):
        self.assertEqual(st.wilcoxon([1, 2], [1, 2]), (0.0, 0, 1.0))


class Bootstrap(unittest.TestCase):
    def test_same_seed_same_interval(self):
        a = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]
        b = [2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0]
        one = st.bootstrap_median_ratio(a, b, seed=1)
        self.assertEqual(one, st.bootstrap_median_ratio(a, b, seed=1))
        self.assertEqual(one[0], 2.25)  # median of 0.5, 1, ..., 4
        self.assertTrue(one[1] <= one[0] <= one[2])

    def test_constant_ratio_has_a_point_interval(self):
        self.assertEqual(st.bootstrap_median_ratio([2, 4, 6], [1, 2, 3]), (2.0, 2.0, 2.0))

    def test_unusable_pairs_are_left_out(self):
        r = st.bootstrap_median_ratio([1.0, 2.0], [0.0, 1.0])
        self.assertEqual(r, (2.0, 2.0, 2.0))
        self.assertTrue(math.isnan(st.bootstrap_median_ratio([1.0], [0.0])[0]))


class RankSum(unittest.TestCase):
    def brute(self, x, y):
        """The plain definition: every way to give len(x) of the pooled values' ranks to x."""
        pooled = list(x) + list(y)
        r = st.ranks(pooled)
        observed = sum(r[: len(x)])
        sums = [sum(r[i] for i in c) for c in itertools.combinations(range(len(r)), len(x))]
        return sum(1 for s in sums if s >= observed - 1e-9) / len(sums)

    def test_exact_counting_equals_the_plain_definition_on_random_inputs(self):
        rng = random.Random(7)
        for _ in range(60):
            x = [rng.choice([0.5, 1.0, 1.5, 2.0, rng.random()]) for _ in range(rng.randint(1, 6))]
            y = [rng.choice([0.5, 1.0, 1.5, 2.0, rng.random()]) for _ in range(rng.randint(1, 6))]
            self.assertAlmostEqual(st.rank_sum_greater(x, y), self.brute(x, y), 12, (x, y))

    def test_five_larger_values_give_one_in_252(self):
        self.assertAlmostEqual(st.rank_sum_greater([5, 6, 7, 8, 9], [0, 1, 2, 3, 4]), 1 / 252)
        self.assertEqual(st.rank_sum_greater([0, 1, 2, 3, 4], [5, 6, 7, 8, 9]), 1.0)
        self.assertEqual(st.rank_sum_greater([], [1.0]), 1.0)


if __name__ == "__main__":
    unittest.main()
