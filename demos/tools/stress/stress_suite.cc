#include "demos/tools/stress/stress_suite.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "demos/tools/stress/stress_cells.h"
#include "plugin/common.h"

namespace taut::stress {

namespace {
// "1/240" for h = 1/240 s.
std::string FormatStep(double h) {
  return "h=1/" + std::to_string(static_cast<int>(std::lround(1.0 / h)));
}

// "1e+05" style for a parameter.
std::string FormatValue(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

// Name of a start shape.
const char* GetStartShapeName(StartShape shape) {
  switch (shape) {
    case StartShape::kMirrored:
      return "mirrored (all inverted)";
    case StartShape::kSquashed:
      return "squashed flat";
    case StartShape::kNodeThrough:
      return "corner node pushed through";
  }
  return "?";
}

// Appends the drop and impact cells (cube falling from 2 cm or thrown down at 10 m/s).
void AppendDropCells(std::vector<SuiteCell>& suite) {
  for (double E : {1e3, 1e5, 1e7, 1e9})
    for (double h : {1.0 / 2000, 1.0 / 240, 1.0 / 60, 1.0 / 30}) {
      DropParams p;
      p.youngs_modulus = E;
      p.h = h;
      suite.push_back({"stiffness x step: 0.2 m tet cube dropped 2 cm, 1 s",
                       "E=" + FormatValue(E) + " " + FormatStep(h),
                       [p](CellResult& r) { RunDropCell(p, r); }});
    }
  for (bool hexes : {false, true})
    for (double E : {1e5, 1e7, 1e9})
      for (double h : {1.0 / 240, 1.0 / 60}) {
        if (hexes && E == 1e9) continue;
        DropParams p;
        p.youngs_modulus = E;
        p.h = h;
        p.speed = 10.0;
        p.height = 0.05;
        p.cells = 3;
        p.hexes = hexes;
        p.duration = 0.5;
        suite.push_back(
            {"impact: 0.2 m cube at 10 m/s onto the ground, 0.5 s",
             std::string(hexes ? "hexes" : "tets") + " E=" + FormatValue(E) + " " + FormatStep(h),
             [p](CellResult& r) { RunDropCell(p, r); }});
      }
}

// Appends the cantilever cells: stiffness x step, strain limits, energy limits.
void AppendBeamCells(std::vector<SuiteCell>& suite) {
  for (double E : {1e3, 1e6, 1e9})
    for (double h : {1.0 / 2000, 1.0 / 30}) {
      BeamParams p;
      p.youngs_modulus = E;
      p.h = h;
      p.steps = static_cast<int>(std::lround(1.0 / h));
      suite.push_back({"stiffness x step: 1 m cantilever (60 tets), 1 s",
                       "E=" + FormatValue(E) + " " + FormatStep(h),
                       [p](CellResult& r) { RunBeamCell(p, r); }});
    }
  for (double d : {0.001, 0.01, 0.1, 0.5}) {
    BeamParams p;
    p.scale = 0.5;
    p.youngs_modulus = 1e5;
    p.h = 1.0 / 240;
    p.steps = 120;
    p.strain_limit = d;
    suite.push_back({"strain limits: 0.5 m soft cantilever (E=1e5, 60 tets), h=1/240, 0.5 s",
                     "+-" + FormatValue(100 * d) + " %",
                     [p](CellResult& r) { RunBeamCell(p, r); }});
  }
  for (bool hexes : {false, true})
    for (double eps : {1e-1, 1e-2, 1e-3, 1e-4}) {
      BeamParams p;
      p.scale = 0.5;
      p.youngs_modulus = 1e5;
      p.h = 1.0 / 240;
      p.steps = 120;
      p.energy_limit_strain = eps;
      p.hexes = hexes;
      suite.push_back({"energy limits: same cantilever (60 tets or 10 hexes), U_max = 1/2 E eps^2",
                       std::string(hexes ? "hexes" : "tets") + " eps=" + FormatValue(eps) +
                           " (U_max density " + FormatValue(0.5 * 1e5 * eps * eps) + " J/m^3)",
                       [p](CellResult& r) { RunBeamCell(p, r); }});
    }
}

// Appends recovery, sliver, spin, mass-ratio, long-run and scale cells.
void AppendOtherCells(std::vector<SuiteCell>& suite) {
  for (bool hexes : {false, true})
    for (int cells : {2, 3})
      for (StartShape shape :
           {StartShape::kMirrored, StartShape::kSquashed, StartShape::kNodeThrough}) {
        if (hexes && cells == 3) continue;
        RecoveryParams p;
        p.shape = shape;
        p.cells = cells;
        p.hexes = hexes;
        suite.push_back({"recovery: 0.2 m cube (E=1e5) starting deformed, h=1/240, 1.5 s",
                         std::string(hexes ? "hexes " : "tets ") + std::to_string(cells) + "^3 " +
                             GetStartShapeName(shape),
                         [p](CellResult& r) { RunRecoveryCell(p, r); }});
      }
  for (double limit : {0.0, 0.05})
    for (double q : {1e-2, 1e-4, 1e-6, 1e-9, 1e-13}) {
      if (limit > 0.0 && (q == 1e-2 || q == 1e-13)) continue;
      SliverParams p;
      p.quality = q;
      p.strain_limit = limit;
      suite.push_back(
          {"slivers: 0.2 m cube (81 tets) with nearly flat tets, dropped, 0.5 s",
           "V/l^3=" + FormatValue(q) + (limit > 0 ? " with +-5 % strain limits" : " no limits"),
           [p](CellResult& r) { RunSliverCell(p, r); }});
    }
  for (double E : {1e4, 1e6, 1e8})
    for (double omega : {10.0, 30.0, 100.0})
      for (double h : {1.0 / 2000, 1.0 / 240, 1.0 / 60}) {
        SpinParams p;
        p.youngs_modulus = E;
        p.omega = omega;
        p.h = h;
        suite.push_back(
            {"spin: free 0.2 m cube, no gravity, no damping, 1 s",
             "E=" + FormatValue(E) + " w=" + FormatValue(omega) + " rad/s " + FormatStep(h),
             [p](CellResult& r) { RunSpinCell(p, r); }});
      }
  for (double friction : {0.5, 0.0})
    for (double ratio : {1.0, 10.0, 100.0, 1000.0}) {
      MassRatioParams p;
      p.ratio = ratio;
      p.friction = friction;
      suite.push_back({"mass ratio: dynamic rigid box on a soft slab, h=1/240, 1 s",
                       FormatValue(ratio) + ":1, friction " + FormatValue(friction),
                       [p](CellResult& r) { RunMassRatioCell(p, r); }});
    }
  suite.push_back({"long run: 100,000 steps at h=1/240 (417 s)",
                   "0.1 m cube resting on the ground, +-5 % strain limits",
                   [](CellResult& r) { RunLongRunCell(LongRunParams(), r); }});
  SpinParams long_spin;
  long_spin.omega = 10.0;
  long_spin.duration = 100000 / 240.0;
  suite.push_back({"long run: 100,000 steps at h=1/240 (417 s)", "free cube spinning at 10 rad/s",
                   [long_spin](CellResult& r) { RunSpinCell(long_spin, r); }});
  for (double scale : {0.001, 0.01, 0.1, 10.0, 30.0})
    suite.push_back({"scale: cantilever (E=1e9) scaled from 1 m, quasi-static, sag vs scale^2",
                     "L=" + FormatValue(scale) + " m",
                     [scale](CellResult& r) { RunScaleCell(scale, 0.01, r); }});
}
}  // namespace

std::vector<SuiteCell> MakeFullSuite() {
  std::vector<SuiteCell> suite;
  AppendDropCells(suite);
  AppendBeamCells(suite);
  AppendOtherCells(suite);
  return suite;
}

std::vector<SuiteCell> MakeSmokeSuite() {
  std::vector<SuiteCell> suite;
  RecoveryParams recovery;
  recovery.duration = 0.25;
  suite.push_back({"smoke", "mirrored tet cube, 60 steps",
                   [recovery](CellResult& r) { RunRecoveryCell(recovery, r); }});
  DropParams impact;
  impact.speed = 10.0;
  impact.height = 0.05;
  impact.duration = 0.1;
  suite.push_back(
      {"smoke", "impact 10 m/s, 24 steps", [impact](CellResult& r) { RunDropCell(impact, r); }});
  SpinParams spin;
  spin.duration = 0.1;
  suite.push_back(
      {"smoke", "spin 30 rad/s, 24 steps", [spin](CellResult& r) { RunSpinCell(spin, r); }});
  SliverParams sliver;
  sliver.quality = 1e-13;
  suite.push_back({"smoke", "sliver below the mesh check (must fail loudly)",
                   [sliver](CellResult& r) { RunSliverCell(sliver, r); }});
  return suite;
}

namespace {
// Reads everything from fd until end of file.
std::string ReadAll(int fd) {
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = read(fd, buffer, sizeof(buffer))) != 0;) {
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    text.append(buffer, static_cast<size_t>(n));
  }
  return text;
}
}  // namespace

CellResult RunSuiteCell(const SuiteCell& cell, bool isolate, double timeout_s) {
  if (!isolate) return RunCellGuarded(cell.group, cell.name, cell.body);
  std::fflush(nullptr);
  int fds[2];
  if (pipe(fds) != 0) return RunCellGuarded(cell.group, cell.name, cell.body);
  const pid_t child = fork();
  if (child == 0) {
    close(fds[0]);
    alarm(static_cast<unsigned>(std::ceil(timeout_s)));
    const std::string text = ToJson(RunCellGuarded(cell.group, cell.name, cell.body)).dump();
    for (size_t done = 0; done < text.size();) {
      const ssize_t n = write(fds[1], text.data() + done, text.size() - done);
      if (n <= 0) _exit(2);
      done += static_cast<size_t>(n);
    }
    _exit(0);
  }
  close(fds[1]);
  const std::string text = ReadAll(fds[0]);
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && !text.empty())
    return CellResultFromJson(nlohmann::json::parse(text));
  CellResult result;
  result.group = cell.group;
  result.name = cell.name;
  result.status = CellStatus::kBroken;
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) {
    result.note = internal::Concat("did not finish within ", timeout_s, " s");
  } else if (WIFSIGNALED(status)) {
    result.note = internal::Concat("crashed: signal ", WTERMSIG(status), " (",
                                   strsignal(WTERMSIG(status)), ")");
  } else {
    result.note = internal::Concat("child exited with status ", WEXITSTATUS(status));
  }
  return result;
}

}  // namespace taut::stress
