/* bind_ifs.c — language binding (being written). */
#include "builtin.h"

int bind_ifs_init(interp *I)
{
    (void)I;
    return 0;
}
