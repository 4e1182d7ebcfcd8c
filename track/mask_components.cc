#include "track/mask_components.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace bouncefit {

int ComponentsWithStats(const cv::Mat& mask, cv::Mat* labels, cv::Mat* stats, cv::Mat* centroids) {
  const int n = cv::connectedComponents(mask, *labels, 8, CV_32S);
  struct Acc {
    int x0 = INT32_MAX, y0 = INT32_MAX, x1 = -1, y1 = -1;
    int64_t area = 0, sx = 0, sy = 0;
  };
  std::vector<Acc> acc(static_cast<size_t>(n));
  // Run by run along each row: a blob's row is one or a few runs of its label.
  for (int j = 0; j < labels->rows; ++j) {
    const int* l = labels->ptr<int>(j);
    for (int i = 0; i < labels->cols;) {
      const int k = l[i];
      int e = i + 1;
      while (e < labels->cols && l[e] == k) ++e;
      if (k > 0) {
        Acc& a = acc[static_cast<size_t>(k)];
        const int64_t len = e - i;
        a.x0 = std::min(a.x0, i), a.x1 = std::max(a.x1, e - 1);
        a.y0 = std::min(a.y0, j), a.y1 = std::max(a.y1, j);
        a.area += len, a.sx += len * (i + e - 1) / 2, a.sy += len * j;
      }
      i = e;
    }
  }
  stats->create(n, cv::CC_STAT_MAX, CV_32S);
  centroids->create(n, 2, CV_64F);
  for (int k = 0; k < n; ++k) {
    const Acc& a = acc[static_cast<size_t>(k)];
    int* st = stats->ptr<int>(k);
    double* c = centroids->ptr<double>(k);
    if (a.area == 0) {  // the background, whose statistics nobody reads
      std::fill(st, st + cv::CC_STAT_MAX, 0);
      c[0] = c[1] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    st[cv::CC_STAT_LEFT] = a.x0, st[cv::CC_STAT_TOP] = a.y0;
    st[cv::CC_STAT_WIDTH] = a.x1 - a.x0 + 1, st[cv::CC_STAT_HEIGHT] = a.y1 - a.y0 + 1;
    st[cv::CC_STAT_AREA] = static_cast<int>(a.area);
    c[0] = static_cast<double>(a.sx) / static_cast<double>(a.area);
    c[1] = static_cast<double>(a.sy) / static_cast<double>(a.area);
  }
  return n;
}

int MaskComponents(const cv::Mat& mask, cv::Mat* labels, cv::Mat* stats, cv::Mat* centroids,
                   cv::Rect* box) {
  *box = cv::boundingRect(mask);
  if (box->area() == 0) {
    labels->release();
    return 1;
  }
  const int n = ComponentsWithStats(mask(*box), labels, stats, centroids);
  for (int k = 1; k < n; ++k) {
    stats->at<int>(k, cv::CC_STAT_LEFT) += box->x;
    stats->at<int>(k, cv::CC_STAT_TOP) += box->y;
    centroids->at<double>(k, 0) += box->x;
    centroids->at<double>(k, 1) += box->y;
  }
  return n;
}

}  // namespace bouncefit
