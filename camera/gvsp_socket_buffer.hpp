#pragma once
// Gives the GigE Vision stream's UDP socket a receive buffer for a whole frame before the first
// frame arrives (see the .cpp for why).

#include <arv.h>

namespace facet {

void presizeStreamSocket(ArvStream* stream, guint payload);

}  // namespace facet
