// `--snapshots T1,T2,… --snapshot-out FILE` of the string and plate subcommands (wave shares the
// flag check): the whole field at the first step at or after each requested time, for the
// figures of docs/validation.md.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "schemes/hamiltonian.h"

namespace hamiltone::cli {

// Refuses one flag without the other, and a snapshot file that is also --out however spelled
// (./a.csv, a symlink or a hard link to it): exit 2 naming --snapshot-out.
void checkSnapshotFlags(const std::string& times, const std::string& file, const std::string& out);

// "t1,t2,..." as step indices: ceil(t / k), each t in [0, steps k], sorted, duplicates merged.
std::vector<long> snapshotSteps(const std::string& times, double k, long steps);

// Writes `header`, then, at each wanted step, the rows of `field(out, t, q)`.
class Snapshots {
 public:
  using Field = std::function<void(std::FILE* out, double t, const Vector& q)>;
  Snapshots(std::vector<long> steps, const char* header, Field field, std::FILE* out);

  // Called with the state at step n, for n = 0, 1, 2, … in order.
  void visit(long n, double t, const Vector& q);

 private:
  std::vector<long> steps_;  // ascending step indices
  std::size_t next_ = 0;
  Field field_;
  std::FILE* out_;
};

// A scheme, held by reference (the implicit references cannot be moved), that shows each state it
// reaches to the snapshots, if any; runToCsv steps this in place of the scheme.
template <class Scheme>
class Snapshotting {
 public:
  Snapshotting(Scheme& scheme, Snapshots* snapshots) : scheme_(scheme), snapshots_(snapshots) {
    show();
  }
  void step() {
    scheme_.step();
    show();
  }
  Energy energy() const { return scheme_.energy(); }
  double dissipated() const { return scheme_.dissipated(); }
  double time() const { return scheme_.time(); }
  const Vector& q() const { return scheme_.q(); }
  const Scheme& scheme() const { return scheme_; }

 private:
  void show() {
    if (snapshots_ != nullptr && scheme_.q().allFinite())
      snapshots_->visit(scheme_.stepIndex(), scheme_.time(), scheme_.q());
  }
  Scheme& scheme_;
  Snapshots* snapshots_;
};

}  // namespace hamiltone::cli
