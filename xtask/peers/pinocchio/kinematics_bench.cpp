// Pinocchio peer benchmark for anim-rigid (`cargo xtask bench --peers`).
//
// Reads a kinematic tree written by the xtask from anim-rigid's model of the same URDF (which
// equals Pinocchio's URDF model to 1e-16, see crates/anim-rigid/tests/pinocchio.rs), builds the
// Pinocchio model with the same specialised joint types its URDF parser would choose (RX, RY, RZ,
// RevoluteUnaligned, PX, PY, PZ, PrismaticUnaligned), and times forwardKinematics and
// computeJointJacobians per call over pre-generated random configurations. Header-only use of
// the `pin` wheel (no URDF parser: the wheel ships no urdfdom headers), compiled by the xtask with
// g++ -O3 -march=native.
//
// usage: kinematics_bench MODEL_FILE CALLS_PER_BATCH
// MODEL_FILE lines: "joint PARENT TYPE AX AY AZ R00 R01 R02 R10 R11 R12 R20 R21 R22 TX TY TZ LOWER UPPER"
// prints one JSON object per line: {"kernel": ..., "ns_per_call": ..., "checksum": ...}

#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/multibody.hpp>

#include <algorithm>
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
    double a[3], r[9], t[3], lo, hi;
    if (!(s >> tag >> parent >> type)) continue;
    for (double& x : a) s >> x;
    for (double& x : r) s >> x;
    for (double& x : t) s >> x;
    s >> lo >> hi;
    if (!s) {
      std::fprintf(stderr, "bad line: %s\n", line.c_str());
      return 2;
    }
    Eigen::Matrix3d rot;
    rot << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    const pinocchio::SE3 placement(rot, Eigen::Vector3d(t[0], t[1], t[2]));
    const Eigen::Vector3d axis(a[0], a[1], a[2]);
    const std::string name = "j" + std::to_string(++count);
    const Eigen::VectorXd e = Eigen::VectorXd::Constant(1, 1e3);
    const Eigen::VectorXd lower = Eigen::VectorXd::Constant(1, lo), upper = Eigen::VectorXd::Constant(1, hi);
    const auto add = [&](const auto& joint) {
      model.addJoint(parent, joint, placement, name, e, e, lower, upper);
    };
    if (type == "RX") add(pinocchio::JointModelRX());
    else if (type == "RY") add(pinocchio::JointModelRY());
    else if (type == "RZ") add(pinocchio::JointModelRZ());
    else if (type == "RU") add(pinocchio::JointModelRevoluteUnaligned(axis));
    else if (type == "PX") add(pinocchio::JointModelPX());
    else if (type == "PY") add(pinocchio::JointModelPY());
    else if (type == "PZ") add(pinocchio::JointModelPZ());
    else if (type == "PU") add(pinocchio::JointModelPrismaticUnaligned(axis));
    else {
      std::fprintf(stderr, "unsupported joint type %s\n", type.c_str());
      return 2;
    }
  }
  pinocchio::Data data(model);
  const int reps = std::atoi(argv[2]);
  const int n = 1024;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::VectorXd> qs;
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd q(model.nq);
    for (int i = 0; i < model.nq; ++i)
      q[i] = model.lowerPositionLimit[i] + (model.upperPositionLimit[i] - model.lowerPositionLimit[i]) * u(rng);
    qs.push_back(q);
  }
  double sink = 0.0;
  const int batches = 15;
  const double fk = median_ns_per_call(
      [&](int i) {
        pinocchio::forwardKinematics(model, data, qs[i % n]);
        sink += data.oMi[model.njoints - 1].translation()[0];
      },
      reps, batches);
  const double jac = median_ns_per_call(
      [&](int i) {
        pinocchio::computeJointJacobians(model, data, qs[i % n]);
        sink += data.J(0, model.nv - 1);
      },
      reps, batches);
  std::printf("{\"kernel\": \"forward_kinematics\", \"ns_per_call\": %.3f, \"nq\": %d, \"checksum\": %.6e}\n", fk,
              model.nq, sink);
  std::printf("{\"kernel\": \"compute_joint_jacobians\", \"ns_per_call\": %.3f, \"nq\": %d, \"checksum\": %.6e}\n",
              jac, model.nq, sink);
  return 0;
}
