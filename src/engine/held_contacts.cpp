#include "ball_physics_sim/engine/held_contacts.h"

#include <algorithm>
#include <cassert>

namespace ball_physics_sim::engine {

const ContactForces* HeldContacts::find(const Contact& contact) const {
  if (contact.first >= by_ball_.size()) return nullptr;
  for (const Held& held : by_ball_[contact.first])
    if (held.contact == contact) return &held.forces;
  return nullptr;
}

bool HeldContacts::add(const Contact& contact, std::optional<std::size_t> other,
                       const ContactForces& forces) {
  if (contains(contact)) return false;
  for (const std::optional<std::size_t> ball : {std::optional(contact.first), other}) {
    if (!ball) continue;
    if (*ball >= by_ball_.size()) by_ball_.resize(*ball + 1);
    by_ball_[*ball].push_back({contact, other, forces});
  }
  return true;
}

std::vector<HeldContacts::Contact> HeldContacts::of(const std::vector<std::size_t>& balls) const {
  std::vector<Contact> contacts;
  for (const std::size_t ball : balls)
    if (ball < by_ball_.size())
      for (const Held& held : by_ball_[ball]) contacts.push_back(held.contact);
  // (In order: their order, and what is done with them in turn, does not hang on the order in
  // which the balls are asked about.)
  std::sort(contacts.begin(), contacts.end());
  contacts.erase(std::unique(contacts.begin(), contacts.end()), contacts.end());
  return contacts;
}

void HeldContacts::erase(const Contact& contact) {
  if (contact.first >= by_ball_.size()) return;
  std::vector<Held>& own = by_ball_[contact.first];
  const auto at = std::find_if(own.begin(), own.end(),
                               [&](const Held& held) { return held.contact == contact; });
  if (at == own.end()) return;
  const std::optional<std::size_t> other = at->other;
  *at = own.back();
  own.pop_back();
  if (!other) return;
  std::vector<Held>& others = by_ball_[*other];
  const auto at_other = std::find_if(others.begin(), others.end(),
                                     [&](const Held& held) { return held.contact == contact; });
  assert(at_other != others.end());  // (each is in both its balls' lists)
  *at_other = others.back();
  others.pop_back();
}

void HeldContacts::clear() { by_ball_.clear(); }

}  // namespace ball_physics_sim::engine
