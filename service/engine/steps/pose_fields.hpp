#pragma once
// Keys that several step kinds share, with one wording: where a step searches and how it
// follows an earlier step's pose.

#include <optional>
#include <string>

#include "config/step_fields.hpp"

namespace facet::service {

template <class P>
void addRelativeTo(config::StepFields<P>& f) {
  f.stepRef("relative_to", &P::relativeTo, &config::StepOffers::pose,
            "Id of an earlier step whose pose this step's positions follow (a step that gives a "
            "pose); without it positions are pixels of the live image.");
}

template <class P>
void addSearch(config::StepFields<P>& f) {
  f.rect("search_region", &P::searchRegion,
         "[x, y, width, height] of the live image searched, pixels; default: all of it.");
  f.number("min_score", &P::minScore, "Lowest match score accepted, 0..1.",
           {.minimum = 0.0, .maximum = 1.0, .exclusiveMinimum = true});
  f.angleRange("angle_range", &P::angleRange,
               "[low, high] rotation searched, degrees, within [-180, 180]; relative to the "
               "relative_to step's angle when the step has one.");
}

}  // namespace facet::service
