/* bindings.c — registers the language bindings of the runtime engines.
 * Each engine's binding lives in its own interp/bind_NAME.c. */
#include "builtin.h"

int bindings_init(interp *I)
{
    (void)I;
    return 0;
}
