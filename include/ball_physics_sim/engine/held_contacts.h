#pragma once

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "ball_physics_sim/engine/friction.h"

namespace ball_physics_sim::engine {

// Resting contacts under load until the next event, with their forces, each found from either
// of its balls: an event asks for the contacts of the few balls it changed, so its work does
// not grow with the contacts held elsewhere in the world.
class HeldContacts {
 public:
  // (ball, key): the key of what the ball touches, as World numbers bodies.
  using Contact = std::pair<std::size_t, std::size_t>;

  // The contact's forces as held, or none if it is not held.
  const ContactForces* find(const Contact& contact) const;
  bool contains(const Contact& contact) const { return find(contact) != nullptr; }
  // Whether the ball has a contact held.
  bool holdsAny(std::size_t ball) const {
    return ball < by_ball_.size() && !by_ball_[ball].empty();
  }
  // Holds a contact of contact.first and, if the key names one, `other` ball. False, and the
  // forces kept as they were, if it is held already.
  bool add(const Contact& contact, std::optional<std::size_t> other, const ContactForces& forces);
  // The held contacts of any of these balls, each once, in order.
  std::vector<Contact> of(const std::vector<std::size_t>& balls) const;
  void erase(const Contact& contact);
  void clear();

 private:
  struct Held {
    Contact contact;
    std::optional<std::size_t> other;  // the other ball, if the key names one
    ContactForces forces;
  };
  // Per ball, the contacts it is in, as contact.first or as the other ball: a few each.
  std::vector<std::vector<Held>> by_ball_;
};

}  // namespace ball_physics_sim::engine
