// Pinocchio's own templates compiled natively: the fair peer of robodyn's kernels (issue 22).
//
// Built by benchmarks/native_peer.py with the compiler and optimisation flags of robodyn's
// kernels, against the headers that the `pin` wheel ships plus Eigen's headers (cmeel-eigen);
// header-only: PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION is not defined, so every algorithm is
// instantiated here, for this CPU, and nothing is linked from libpinocchio*.so.
//
//   pinocchio_bench MODEL STATES OUT REPEATS NCHECK
//
// MODEL: text, written by native_peer.py from the Python Pinocchio model of the benchmark (the
//   same joints, placements, inertias, armature and gravity):
//     nq N
//     gravity gx gy gz
//     joint TYPE PARENT ax ay az R00..R22 px py pz mass cx cy cz Ixx Ixy Ixz Iyy Iyz Izz armature
//   (N lines; TYPE is RX, RY, RZ, PX, PY, PZ, RU or PU, the last two with the axis a).
// STATES: little-endian binary: int64 count, int64 nq, then q, v, a, tau as count x nq doubles.
// OUT: binary doubles: rnea(q, v, a) and aba(q, v, tau) (LOCAL convention, the default; the
//   WORLD convention is timed too, its results are not written) for every state (count x nq each), then
//   for the first NCHECK states ddq/dq, ddq/dv and Minv of computeABADerivatives(q, v, tau),
//   each nq x nq row-major.
// stdout: one JSON line, seconds per repeat of each kernel's loop over all states (the
//   benchmark runs REPEATS=1 once per round, taking turns with the other libraries).
//
// Timed loops: one thread, one pinocchio::Data, states read in place (Eigen::Map, no copies);
// rnea and aba copy their nq results into the output array (as robodyn writes its output);
// computeABADerivatives leaves its three matrices in Data (the peer at its best).

#include <pinocchio/multibody.hpp>  // first: Model, Data (Pinocchio 4 layout)
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using Model = pinocchio::Model;
using Data = pinocchio::Data;
using Vec3 = Eigen::Vector3d;
using ConstMap = Eigen::Map<const Eigen::VectorXd>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

pinocchio::JointIndex add_joint(Model &model, const std::string &type, pinocchio::JointIndex parent,
                                const pinocchio::SE3 &placement, const Vec3 &axis,
                                const std::string &name) {
  if (type == "RX") return model.addJoint(parent, pinocchio::JointModelRX(), placement, name);
  if (type == "RY") return model.addJoint(parent, pinocchio::JointModelRY(), placement, name);
  if (type == "RZ") return model.addJoint(parent, pinocchio::JointModelRZ(), placement, name);
  if (type == "PX") return model.addJoint(parent, pinocchio::JointModelPX(), placement, name);
  if (type == "PY") return model.addJoint(parent, pinocchio::JointModelPY(), placement, name);
  if (type == "PZ") return model.addJoint(parent, pinocchio::JointModelPZ(), placement, name);
  if (type == "RU")
    return model.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(axis), placement, name);
  if (type == "PU")
    return model.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(axis), placement, name);
  throw std::runtime_error("unknown joint type " + type);
}

Model read_model(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string key;
  int nq = 0;
  Vec3 gravity;
  in >> key >> nq >> key >> gravity[0] >> gravity[1] >> gravity[2];
  Model model;
  std::vector<double> armature;
  for (int j = 0; j < nq; ++j) {
    std::string type;
    long parent = 0;
    Vec3 axis, p, c;
    Eigen::Matrix3d R;
    double mass, ixx, ixy, ixz, iyy, iyz, izz, arm;
    in >> key >> type >> parent >> axis[0] >> axis[1] >> axis[2];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) in >> R(r, k);
    in >> p[0] >> p[1] >> p[2] >> mass >> c[0] >> c[1] >> c[2];
    in >> ixx >> ixy >> ixz >> iyy >> iyz >> izz >> arm;
    if (!in || key != "joint") throw std::runtime_error("malformed joint line in " + path);
    const auto id = add_joint(model, type, static_cast<pinocchio::JointIndex>(parent),
                              pinocchio::SE3(R, p), axis, "j" + std::to_string(j + 1));
    Eigen::Matrix3d I;
    I << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
    model.appendBodyToJoint(id, pinocchio::Inertia(mass, c, I), pinocchio::SE3::Identity());
    armature.push_back(arm);
  }
  if (model.nv != nq) throw std::runtime_error("model has nv != nq");
  model.armature = Eigen::Map<Eigen::VectorXd>(armature.data(), nq);
  model.gravity.linear(gravity);
  return model;
}

struct States {
  std::int64_t count = 0, nq = 0;
  std::vector<double> q, v, a, tau;
};

States read_states(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  States s;
  in.read(reinterpret_cast<char *>(&s.count), sizeof s.count);
  in.read(reinterpret_cast<char *>(&s.nq), sizeof s.nq);
  for (auto *arr : {&s.q, &s.v, &s.a, &s.tau}) {
    arr->resize(static_cast<std::size_t>(s.count * s.nq));
    in.read(reinterpret_cast<char *>(arr->data()),
            static_cast<std::streamsize>(arr->size() * sizeof(double)));
  }
  if (!in) throw std::runtime_error("truncated states file " + path);
  return s;
}

template <typename F> double seconds(F &&loop) {
  const auto start = std::chrono::steady_clock::now();
  loop();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct Kernels {
  const Model &model;
  Data &data;
  const States &s;
  std::vector<double> &tau_out, &qdd_out;

  ConstMap at(const std::vector<double> &arr, std::int64_t k) const {
    return ConstMap(arr.data() + k * s.nq, s.nq);
  }
  void rnea() {
    for (std::int64_t k = 0; k < s.count; ++k)
      Eigen::Map<Eigen::VectorXd>(tau_out.data() + k * s.nq, s.nq) =
          pinocchio::rnea(model, data, at(s.q, k), at(s.v, k), at(s.a, k));
  }
  void aba(pinocchio::Convention convention) {
    for (std::int64_t k = 0; k < s.count; ++k)
      Eigen::Map<Eigen::VectorXd>(qdd_out.data() + k * s.nq, s.nq) =
          pinocchio::aba(model, data, at(s.q, k), at(s.v, k), at(s.tau, k), convention);
  }
  void aba_derivatives(std::int64_t count) {
    for (std::int64_t k = 0; k < count; ++k)
      pinocchio::computeABADerivatives(model, data, at(s.q, k), at(s.v, k), at(s.tau, k));
  }
};

void write_json(const std::vector<std::pair<std::string, std::vector<double>>> &times) {
  std::ostringstream out;
  out.precision(9);
  out << "{";
  for (std::size_t i = 0; i < times.size(); ++i) {
    out << (i ? ", " : "") << '"' << times[i].first << "\": [";
    for (std::size_t r = 0; r < times[i].second.size(); ++r)
      out << (r ? ", " : "") << times[i].second[r];
    out << "]";
  }
  out << ", \"eigen\": \"" << EIGEN_WORLD_VERSION << '.' << EIGEN_MAJOR_VERSION << '.'
      << EIGEN_MINOR_VERSION << "\", \"pinocchio\": \"" << PINOCCHIO_VERSION << "\"}";
  std::cout << out.str() << std::endl;
}

}  // namespace

int main(int argc, char **argv) {
  if (argc != 6) {
    std::cerr << "usage: pinocchio_bench MODEL STATES OUT REPEATS NCHECK\n";
    return 2;
  }
  try {
    const Model model = read_model(argv[1]);
    const States s = read_states(argv[2]);
    if (s.nq != model.nq) throw std::runtime_error("states and model differ in nq");
    const int repeats = std::atoi(argv[4]);
    const std::int64_t ncheck = std::min<std::int64_t>(std::atoll(argv[5]), s.count);
    Data data(model);
    std::vector<double> tau_out(s.q.size()), qdd_out(s.q.size());
    Kernels kernels{model, data, s, tau_out, qdd_out};
    std::vector<std::pair<std::string, std::vector<double>>> times = {
        {"rnea", {}}, {"aba_world", {}}, {"aba", {}}, {"aba_derivatives", {}}};
    kernels.aba_derivatives(std::min<std::int64_t>(s.count, 100));  // warm caches and pages
    for (int r = 0; r < repeats; ++r) {  // kernels interleaved: a load burst hits all alike
      times[0].second.push_back(seconds([&] { kernels.rnea(); }));
      times[1].second.push_back(seconds([&] { kernels.aba(pinocchio::Convention::WORLD); }));
      times[2].second.push_back(seconds([&] { kernels.aba(pinocchio::Convention::LOCAL); }));
      times[3].second.push_back(seconds([&] { kernels.aba_derivatives(s.count); }));
    }
    std::ofstream out(argv[3], std::ios::binary);
    out.write(reinterpret_cast<const char *>(tau_out.data()),
              static_cast<std::streamsize>(tau_out.size() * sizeof(double)));
    out.write(reinterpret_cast<const char *>(qdd_out.data()),
              static_cast<std::streamsize>(qdd_out.size() * sizeof(double)));
    const auto n = static_cast<Eigen::Index>(s.nq);
    for (std::int64_t k = 0; k < ncheck; ++k) {
      pinocchio::computeABADerivatives(model, data, kernels.at(s.q, k), kernels.at(s.v, k),
                                       kernels.at(s.tau, k));
      for (const auto *m : {&data.ddq_dq, &data.ddq_dv, &data.Minv}) {
        const RowMatrix row = m->topLeftCorner(n, n);
        out.write(reinterpret_cast<const char *>(row.data()),
                  static_cast<std::streamsize>(n * n * sizeof(double)));
      }
    }
    if (!out) throw std::runtime_error(std::string("cannot write ") + argv[3]);
    write_json(times);
  } catch (const std::exception &e) {
    std::cerr << "pinocchio_bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
