/* test_textline.c — header lines (textline.h): LF and CRLF endings, a last
 * line without '\n', an empty line, a line cut to the buffer with its full
 * length returned, and the end. */
#include <string.h>

#include "check.h"
#include "textline.h"

int main(void)
{
    const char *text = "ply\r\nformat ascii 1.0\n\nabcdefghij\nlast";
    const unsigned char *d = (const unsigned char *)text;
    size_t n = strlen(text), pos = 0;
    char buf[8];
    CHECK(textline_next(d, n, &pos, buf, sizeof buf) == 3 && strcmp(buf, "ply") == 0 && pos == 5, "CRLF line");
    CHECK(textline_next(d, n, &pos, buf, sizeof buf) == 16 && strcmp(buf, "format ") == 0 && pos == 22,
          "cut to 7 bytes, full length 16: '%s'", buf);
    CHECK(textline_next(d, n, &pos, buf, sizeof buf) == 0 && buf[0] == 0 && pos == 23, "empty line");
    CHECK(textline_next(d, n, &pos, buf, sizeof buf) == 10 && strcmp(buf, "abcdefg") == 0 && pos == 34, "cut line");
    CHECK(textline_next(d, n, &pos, buf, sizeof buf) == 4 && strcmp(buf, "last") == 0 && pos == n,
          "last line without a newline");
    CHECK(textline_next(d, n, &pos, buf, sizeof buf) == -1 && pos == n, "the end");
    return check_done("test_textline");
}
