// One body, one thread at a time (issue 48 item 9). A solve, a cut or a needle step runs
// without Python's GIL, so two threads could drive one body at once: two solvers on one body
// then overwrite each other's displacement and work vectors. Each such operation claims its
// body for its duration; a claim from another thread while one is held throws BodyInUse at
// once, naming what holds it. The same thread may claim again (a needle step's solves, a
// cutter's reads of the state it is cutting).
#pragma once

#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace snede {

class BodyInUse : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ExclusiveUse {
 public:
  // Released when destroyed.
  class Claim {
   public:
    Claim(Claim&& other) noexcept : use_(other.use_) { other.use_ = nullptr; }
    Claim(const Claim&) = delete;
    Claim& operator=(const Claim&) = delete;
    Claim& operator=(Claim&&) = delete;
    ~Claim();

   private:
    friend class ExclusiveUse;
    explicit Claim(ExclusiveUse* use) : use_(use) {}
    ExclusiveUse* use_;
  };

  // `what` names the operation ("a static solve") for the other thread's error.
  [[nodiscard]] Claim claim(const std::string& what);

 private:
  std::mutex mutex_;
  std::thread::id owner_;
  int depth_ = 0;
  std::string holder_;
};

}  // namespace snede
