// One run of reentrant qhull over 3-D points, for the convex hull and the Delaunay triangulation (private to cpp/).
//
// qhull reports errors by printing them and keeps its memory in the qhT it was given: QhullRun catches the printed
// message for the exception and frees qhull's memory when it goes out of scope, whatever happens in between.
#pragma once

#include <Eigen/Core>

#include <cstdio>
#include <string>
#include <vector>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace snakehead {

class QhullRun {
 public:
  // Runs qhull with `flags` (e.g. "qhull Qt") on the points; ok() says whether it succeeded.
  QhullRun(const std::vector<Eigen::Vector3d>& points, const char* flags) : coords_(points.size() * 3) {
    for (std::size_t k = 0; k < points.size(); ++k)
      for (int d = 0; d < 3; ++d) coords_[3 * k + d] = points[k][d];
    err_ = std::tmpfile();
    qh_zero(qh, err_ ? err_ : stderr);
    std::string options(flags);
    status_ = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords_.data(), False, options.data(), nullptr,
                           err_ ? err_ : stderr);
  }
  QhullRun(const QhullRun&) = delete;
  QhullRun& operator=(const QhullRun&) = delete;
  ~QhullRun() {
    qh_freeqhull(qh, !qh_ALL);
    int curlong = 0, totlong = 0;
    qh_memfreeshort(qh, &curlong, &totlong);
    if (err_) std::fclose(err_);
  }

  bool ok() const { return status_ == 0; }
  // The first line qhull printed about its failure ("" when it succeeded or printed nothing).
  std::string error() const {
    std::string message;
    if (ok() || !err_) return message;
    std::rewind(err_);
    char buf[512];
    while (std::fgets(buf, sizeof buf, err_) && message.size() < 400) message += buf;
    return message.substr(0, message.find('\n'));
  }

  qhT storage{};
  qhT* qh = &storage;  // for qhull's macros (FORALLfacets etc. expect a variable named qh)

 private:
  std::vector<coordT> coords_;
  std::FILE* err_ = nullptr;
  int status_ = -1;
};

}  // namespace snakehead
