// The valet task's layer of the trajectory image: the lot's slots, its
// walls, poles and parked cars, the target slot, the stack's planned
// manoeuvre (forward and reverse legs) and the car as it ended.
#ifndef ADSE_ANALYSIS_PICTURES_INTERNAL_PARKING_LAYER_IMPL_H_
#define ADSE_ANALYSIS_PICTURES_INTERNAL_PARKING_LAYER_IMPL_H_

#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "analysis/metrics/parking_metrics.h"
#include "analysis/pictures/internal/drawing_impl.h"
#include "analysis/pictures/pictures.h"

namespace adse::analysis::internal {

using ToPixel = std::function<cv::Point2d(double x_m, double y_m)>;

// Corners of a box (centre, heading along its length) in pixels.
std::vector<cv::Point2d> BoxPx(double cx, double cy, double yaw, double length,
                               double width, const ToPixel& px);

// The closed outline through `corners`.
void Outline(cv::Mat* img, std::vector<cv::Point2d> corners,
             const cv::Scalar& colour, int thickness,
             cv::LineTypes type = cv::LINE_AA);

// Under everything else: slots (outlines), obstacles (filled), the target
// slot (a thick outline).
void DrawParkingLot(cv::Mat* img, const runfile::ParkingRecord& parking,
                    const ToPixel& px, const Style& s);

// Over the trajectory: plans a later one replaced (pale), the planned
// manoeuvre, forward and reverse legs in their own colours, the car's body at
// each contact with an obstacle (with a dot where they met) and at the run's
// last sample.
void DrawParkingManoeuvre(cv::Mat* img, const runfile::RunData& run,
                          const std::vector<ParkingContact>& contacts,
                          const ToPixel& px, const Style& s);

// A contact's meeting point: a red dot ringed in black.
void DrawContactMarker(cv::Mat* img, cv::Point2d at, const Style& s);

// The detail panel (drawn into `panel`, which clips): the manoeuvre's
// surroundings enlarged — lanes (world coordinates), the lot, the
// trajectory, the plan, the contacts and the car at the end, with a scale
// bar and a caption.
void DrawParkingDetail(cv::Mat* panel, const runfile::RunData& run,
                       const std::vector<ParkingContact>& contacts,
                       const std::vector<std::vector<cv::Point2d>>& lanes,
                       const Style& s);

}  // namespace adse::analysis::internal

#endif  // ADSE_ANALYSIS_PICTURES_INTERNAL_PARKING_LAYER_IMPL_H_
