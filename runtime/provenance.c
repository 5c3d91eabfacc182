/* provenance.c — the process-wide recipe and the comment writers (provenance.h). */
#include "provenance.h"

#include <string.h>

static prov current;
static int is_set;

void prov_set(const prov *p)
{
    if (p)
        current = *p;
    is_set = p != NULL;
}

const prov *prov_get(void) { return is_set ? &current : NULL; }

void prov_put_lines(bytebuf *out, const char *prefix)
{
    if (!is_set || !current.header)
        return;
    const char *s = current.header, *end = s + current.header_len;
    while (s < end) {
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        size_t n = nl ? (size_t)(nl - s) : (size_t)(end - s);
        bytebuf_append(out, prefix, strlen(prefix));
        bytebuf_append(out, s, n);
        bytebuf_byte(out, '\n');
        s += n + 1;
    }
}

void prov_put_xml_comment(bytebuf *out)
{
    if (!is_set || !current.header)
        return;
    bytebuf_printf(out, "<!-- frac recipe\n");
    for (size_t i = 0; i < current.header_len; i++) {
        char c = current.header[i];
        if (c == '-' && i > 0 && current.header[i - 1] == '-')
            bytebuf_append(out, "\\x2d", 4);
        else
            bytebuf_byte(out, (unsigned char)c);
    }
    bytebuf_printf(out, "-->\n");
}
