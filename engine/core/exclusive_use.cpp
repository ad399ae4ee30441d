#include "core/exclusive_use.hpp"

namespace snede {

ExclusiveUse::Claim ExclusiveUse::claim(const std::string& what) {
  const std::lock_guard lock(mutex_);
  if (depth_ > 0 && owner_ != std::this_thread::get_id())
    throw BodyInUse(what + " was refused: the body is in use by " + holder_ +
                    " in another thread. One body takes one solve, cut or needle step at a time: wait for the " +
                    "other to end (join its thread) before starting this one");
  if (depth_++ == 0) {
    owner_ = std::this_thread::get_id();
    holder_ = what;
  }
  return Claim(this);
}

ExclusiveUse::Claim::~Claim() {
  if (!use_) return;
  const std::lock_guard lock(use_->mutex_);
  if (--use_->depth_ == 0) use_->owner_ = std::thread::id();
}

}  // namespace snede
