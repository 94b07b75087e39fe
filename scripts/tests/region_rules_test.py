#!/usr/bin/env python3
"""Rule O of scripts/region_rules.py (hem_offset) on hand-written localisations: it is scored in a registered test
(docs/preregistrations/session87.md), so a slip here would mislead it."""
import importlib.util
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
spec = importlib.util.spec_from_file_location("region_rules", os.path.join(HERE, "..", "region_rules.py"))
regions = importlib.util.module_from_spec(spec)
spec.loader.exec_module(regions)


def localisation(region, lead, offset_mm, placed_by_views=False):
    """A report's localisation: the region, the feature group (or "stable", "camera", None) that placed it, the hem
    centre's offset in mm."""
    groups = {name: {"ratio": 0.5, "difference_mm": 1.0} for name in
              ("harmonics", "off_centre", "sorted_radii", "hem_height", "skirt_height", "skirt_spread", "folds")}
    groups["off_centre"]["difference_mm"] = offset_mm
    return {"region": region, "dominant_feature": lead, "feature_groups": groups, "placed_by_views": placed_by_views}


class HemOffset(unittest.TestCase):
    def test_a_skirt_gap_a_group_placed_goes_to_the_hem_where_the_centre_lies_off(self):
        self.assertEqual(regions.hem_offset(localisation("skirt", "hem_height", 6.5), 6.5), "hem")
        self.assertEqual(regions.hem_offset(localisation("skirt", "folds", 9.0), 6.5), "hem")
        self.assertEqual(regions.hem_offset(localisation("skirt", "hem_height", 6.4), 6.5), "skirt")

    def test_other_regions_and_placements_stay_as_run(self):
        self.assertEqual(regions.hem_offset(localisation("hem", "off_centre", 9.0), 6.5), "hem")
        self.assertEqual(regions.hem_offset(localisation("top", "stable", 9.0), 6.5), "top")
        self.assertEqual(regions.hem_offset(localisation("global", None, 9.0), 6.5), "global")
        self.assertEqual(regions.hem_offset(localisation("skirt", "hem_height", 9.0, placed_by_views=True), 6.5),
                         "skirt")  # rule M's placement by the views stands
        self.assertEqual(regions.hem_offset(localisation("skirt", None, 9.0, placed_by_views=True), 6.5), "skirt")


class NearestGroup(unittest.TestCase):
    def with_ratios(self, region, lead, ratios, skirt_enrichment=1.0, hem_enrichment=1.2, placed_by_views=False):
        loc = localisation(region, lead, 1.0, placed_by_views)
        for name, ratio in ratios.items():
            loc["feature_groups"][name]["ratio"] = ratio
        loc["regions"] = [{"region": "skirt", "enrichment": skirt_enrichment},
                          {"region": "hem", "enrichment": hem_enrichment}]
        return loc

    def test_a_gap_nothing_places_goes_where_a_group_comes_nearest_its_floor(self):
        self.assertEqual(regions.nearest_group(self.with_ratios("global", None, {"skirt_spread": 0.9})), "skirt")
        self.assertEqual(regions.nearest_group(self.with_ratios("global", "", {"off_centre": 0.95})), "hem")
        # An outline group: the hem unless the skirt's residual is the denser.
        self.assertEqual(regions.nearest_group(self.with_ratios("global", None, {"hem_height": 0.9})), "hem")
        self.assertEqual(regions.nearest_group(self.with_ratios("global", None, {"hem_height": 0.9},
                                                                skirt_enrichment=1.5)), "skirt")

    def test_a_placed_gap_stays_as_run(self):
        self.assertEqual(regions.nearest_group(self.with_ratios("global", "stable", {"skirt_spread": 0.9})), "global")
        self.assertEqual(regions.nearest_group(self.with_ratios("global", "camera", {"skirt_spread": 0.9})), "global")
        self.assertEqual(regions.nearest_group(self.with_ratios("hem", "hem_height", {"skirt_spread": 0.9})), "hem")
        self.assertEqual(regions.nearest_group(self.with_ratios("global", None, {"skirt_spread": 0.9},
                                                                placed_by_views=True)), "global")


if __name__ == "__main__":
    unittest.main()
