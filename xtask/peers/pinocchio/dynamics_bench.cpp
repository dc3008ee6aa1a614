// Pinocchio peer benchmark for anim-rigid's dynamics (`cargo xtask bench --peers`).
//
// Reads the kinematic tree written by the xtask from anim-rigid's model of a URDF (joint types
// as Pinocchio's URDF parser chooses them, placements, and each body's inertia; the models agree
// with Pinocchio's own URDF models to 1e-15, see crates/anim-rigid/tests/pinocchio_dynamics.rs),
// builds the Pinocchio model, and times rnea, crba and aba per call over pre-generated random
// (q, v, a, tau), with both of Pinocchio's conventions for crba and aba (LOCAL, the default, and
// WORLD). Header-only use of the `pin` wheel, compiled by the xtask with g++ -O3 -march=native.
//
// usage: dynamics_bench MODEL_FILE CALLS_PER_BATCH
// MODEL_FILE lines: "joint PARENT TYPE AX AY AZ R00..R22 TX TY TZ LOWER UPPER MASS CX CY CZ I00..I22"
// TYPE: RX RY RZ RU (revolute), PX PY PZ PU (prismatic), RUBX RUBY RUBZ RUBU (revolute without
// limits, q = (cos, sin)), FF (free flyer, q = (x, y, z, qx, qy, qz, qw)).
// prints one JSON object per line: {"kernel": ..., "ns_per_call": ..., "checksum": ...}

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using Clock = std::chrono::steady_clock;

template <typename F>
double median_ns_per_call(F&& f, int calls_per_batch, int batches) {
  std::vector<double> t;
  for (int b = 0; b < batches; ++b) {
    const auto start = Clock::now();
    for (int i = 0; i < calls_per_batch; ++i) f(i);
    const auto end = Clock::now();
    t.push_back(std::chrono::duration<double, std::nano>(end - start).count() / calls_per_batch);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s MODEL_FILE CALLS_PER_BATCH\n", argv[0]);
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "cannot open %s\n", argv[1]);
    return 2;
  }
  pinocchio::Model model;
  std::string line;
  int count = 0;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag, type;
    int parent;
    double a[3], r[9], t[3], lo, hi, mass, c[3], inertia[9];
    if (!(s >> tag >> parent >> type)) continue;
    for (double& x : a) s >> x;
    for (double& x : r) s >> x;
    for (double& x : t) s >> x;
    s >> lo >> hi >> mass;
    for (double& x : c) s >> x;
    for (double& x : inertia) s >> x;
    if (!s) {
      std::fprintf(stderr, "bad line (dynamics needs the inertia fields): %s\n", line.c_str());
      return 2;
    }
    Eigen::Matrix3d rot;
    rot << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    const pinocchio::SE3 placement(rot, Eigen::Vector3d(t[0], t[1], t[2]));
    const Eigen::Vector3d axis(a[0], a[1], a[2]);
    const std::string name = "j" + std::to_string(++count);
    const Eigen::VectorXd e = Eigen::VectorXd::Constant(1, 1e3);
    const Eigen::VectorXd lower = Eigen::VectorXd::Constant(1, lo), upper = Eigen::VectorXd::Constant(1, hi);
    pinocchio::JointIndex id = 0;
    const auto add = [&](const auto& joint) { id = model.addJoint(parent, joint, placement, name, e, e, lower, upper); };
    // (cos, sin) of a revolute joint without limits: two configuration bounds.
    const Eigen::VectorXd lo2 = Eigen::VectorXd::Constant(2, -1.0), hi2 = Eigen::VectorXd::Constant(2, 1.0);
    const auto add_unbounded = [&](const auto& joint) { id = model.addJoint(parent, joint, placement, name, e, e, lo2, hi2); };
    if (type == "RX") add(pinocchio::JointModelRX());
    else if (type == "RY") add(pinocchio::JointModelRY());
    else if (type == "RZ") add(pinocchio::JointModelRZ());
    else if (type == "RU") add(pinocchio::JointModelRevoluteUnaligned(axis));
    else if (type == "PX") add(pinocchio::JointModelPX());
    else if (type == "PY") add(pinocchio::JointModelPY());
    else if (type == "PZ") add(pinocchio::JointModelPZ());
    else if (type == "PU") add(pinocchio::JointModelPrismaticUnaligned(axis));
    else if (type == "RUBX") add_unbounded(pinocchio::JointModelRUBX());
    else if (type == "RUBY") add_unbounded(pinocchio::JointModelRUBY());
    else if (type == "RUBZ") add_unbounded(pinocchio::JointModelRUBZ());
    else if (type == "RUBU") add_unbounded(pinocchio::JointModelRevoluteUnboundedUnaligned(axis));
    else if (type == "FF") {
      // Bounds of the translation; the quaternion is drawn apart.
      const Eigen::VectorXd e6 = Eigen::VectorXd::Constant(6, 1e3);
      const Eigen::VectorXd lo7 = Eigen::VectorXd::Constant(7, -1.0), hi7 = Eigen::VectorXd::Constant(7, 1.0);
      id = model.addJoint(parent, pinocchio::JointModelFreeFlyer(), placement, name, e6, e6, lo7, hi7);
    }
    else {
      std::fprintf(stderr, "unsupported joint type %s\n", type.c_str());
      return 2;
    }
    Eigen::Matrix3d i3;
    i3 << inertia[0], inertia[1], inertia[2], inertia[3], inertia[4], inertia[5], inertia[6], inertia[7], inertia[8];
    model.appendBodyToJoint(id, pinocchio::Inertia(mass, Eigen::Vector3d(c[0], c[1], c[2]), i3), pinocchio::SE3::Identity());
  }
  pinocchio::Data data(model);
  const int reps = std::atoi(argv[2]);
  const int n = 1024;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::VectorXd> qs, vs, as, taus;
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd q(model.nq), v(model.nv), acc(model.nv), tau(model.nv);
    for (pinocchio::JointIndex j = 1; j < (pinocchio::JointIndex)model.njoints; ++j) {
      const int iq = model.joints[j].idx_q();
      const std::string kind = model.joints[j].shortname();
      if (kind == "JointModelFreeFlyer") {
        for (int i = 0; i < 3; ++i) q[iq + i] = 2.0 * u(rng) - 1.0;
        Eigen::Vector4d quat(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
        q.segment<4>(iq + 3) = quat.normalized();
      } else if (kind.rfind("JointModelRUB", 0) == 0 || kind == "JointModelRevoluteUnboundedUnaligned") {
        const double theta = 2.0 * M_PI * u(rng) - M_PI;
        q[iq] = std::cos(theta);
        q[iq + 1] = std::sin(theta);
      } else {
        q[iq] = model.lowerPositionLimit[iq] + (model.upperPositionLimit[iq] - model.lowerPositionLimit[iq]) * u(rng);
      }
    }
    for (int i = 0; i < model.nv; ++i) {
      v[i] = 4.0 * u(rng) - 2.0;
      acc[i] = 6.0 * u(rng) - 3.0;
      tau[i] = 20.0 * u(rng) - 10.0;
    }
    qs.push_back(q);
    vs.push_back(v);
    as.push_back(acc);
    taus.push_back(tau);
  }
  double sink = 0.0;
  const int batches = 15;
  const int last = model.nv - 1;
  const double rnea = median_ns_per_call(
      [&](int i) {
        const int k = i % n;
        pinocchio::rnea(model, data, qs[k], vs[k], as[k]);
        sink += data.tau[last];
      },
      reps, batches);
  const double crba_local = median_ns_per_call(
      [&](int i) {
        pinocchio::crba(model, data, qs[i % n], pinocchio::Convention::LOCAL);
        sink += data.M(0, last);
      },
      reps, batches);
  const double crba_world = median_ns_per_call(
      [&](int i) {
        pinocchio::crba(model, data, qs[i % n], pinocchio::Convention::WORLD);
        sink += data.M(0, last);
      },
      reps, batches);
  const double aba_local = median_ns_per_call(
      [&](int i) {
        const int k = i % n;
        pinocchio::aba(model, data, qs[k], vs[k], taus[k], pinocchio::Convention::LOCAL);
        sink += data.ddq[last];
      },
      reps, batches);
  const double aba_world = median_ns_per_call(
      [&](int i) {
        const int k = i % n;
        pinocchio::aba(model, data, qs[k], vs[k], taus[k], pinocchio::Convention::WORLD);
        sink += data.ddq[last];
      },
      reps, batches);
  const auto print = [&](const char* kernel, double ns) {
    std::printf("{\"kernel\": \"%s\", \"ns_per_call\": %.3f, \"nv\": %d, \"checksum\": %.6e}\n", kernel, ns, model.nv, sink);
  };
  print("rnea", rnea);
  print("crba_local", crba_local);
  print("crba_world", crba_world);
  print("aba_local", aba_local);
  print("aba_world", aba_world);
  return 0;
}
