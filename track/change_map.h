#pragma once
// What changed between two frames, in the finder's small YCrCb copies, and the noise of it.
#include <opencv2/core.hpp>

namespace bouncefit {

// |dY| + |dCr| + |dCb| of two CV_8UC3 images of one size, saturated to 255, into `d`
// (CV_8U; cv::Exception for other types or sizes, as cv::absdiff). 16 pixels a step with OpenCV's universal intrinsics: the per-pixel loop after
// cv::absdiff was a sixth of a held lock's tracking, in instructions.
void ChangeMap(const cv::Mat& a, const cv::Mat& b, cv::Mat& d);

// The median of every 4th pixel of every 4th row of a CV_8U image (the upper of an even
// count's middle two; 0 for none), from their histogram (a sort of the sample took 4% of a
// held lock's tracking time).
int MedianOfEvery4th(const cv::Mat& d);

// A CV_8U mask closed in place with the 3x3 cross (cv::getStructuringElement's 3x3 ellipse):
// each pixel the largest of itself and its four neighbours, then the smallest, the frame's
// outside taking no part: cv::morphologyEx's MORPH_CLOSE with its default border, 16 pixels a
// step (OpenCV's general kernel loop was 14% of a search for the ball, in instructions).
void CloseByCross(cv::Mat& mask);

}  // namespace bouncefit
