/* lineedit.h — a small line editor with history for the REPL (POSIX termios).
 *
 * Written for frac (no readline/libedit). One editor reads lines from in_fd
 * and draws on out_fd:
 *
 *   lineedit *le = lineedit_new(0, 1, "/home/u/.frac_history", 1000);
 *   char *line;
 *   for (;;) {
 *       lineedit_result r = lineedit_read(le, "> ", &line);
 *       if (r == LINEEDIT_INTERRUPT) continue;     // Ctrl-C: fresh prompt
 *       if (r != LINEEDIT_LINE) break;             // EOF or ERROR
 *       lineedit_history_add(le, line);
 *       ... evaluate line ...
 *       free(line);
 *   }
 *   lineedit_free(le);                             // saves the history
 *
 * Modes, chosen once by lineedit_new:
 *   - raw: in_fd is a terminal and TERM is not "dumb". The terminal is put in
 *     raw mode (no echo, no canonical input, no ISIG, no output processing)
 *     for the duration of one lineedit_read only and restored before it
 *     returns, whatever the outcome. Keys are listed in docs/repl-keys.md.
 *   - dumb: in_fd is a terminal but TERM=dumb (e.g. an Emacs shell buffer):
 *     the prompt is written and a line is read in the terminal's own cooked
 *     mode; no escape sequences are written.
 *   - piped: in_fd is not a terminal: no prompt, no raw mode, no escape
 *     sequences; a line ends at '\n' (a '\r' before it is dropped) and a
 *     final line without '\n' is still returned. Input is buffered inside
 *     the editor, so all reads of in_fd must go through it.
 *   In the dumb and piped modes, a read interrupted by a signal (EINTR, e.g.
 *   the caller's SIGINT handler without SA_RESTART) gives LINEEDIT_INTERRUPT
 *   and the partial line is dropped.
 *
 * Results of lineedit_read: LINEEDIT_LINE with *line a malloc'd,
 * NUL-terminated line without the newline (the caller frees it);
 * LINEEDIT_EOF on Ctrl-D on an empty line (raw mode; a newline is written)
 * or end of input; LINEEDIT_INTERRUPT on Ctrl-C (raw mode: "^C" and a newline
 * are written, the current line is dropped, the caller shows a fresh
 * prompt); LINEEDIT_ERROR when reading or writing the terminal failed
 * (lineedit_errmsg says why). *line is NULL unless the result is LINE.
 *
 * Text is UTF-8. Every code point counts as one column (East Asian wide
 * characters and combining marks are not measured: they are rare in frac
 * sources and would need a width table). Invalid UTF-8 bytes typed are
 * ignored. The prompt must be plain text without escape sequences (its
 * width is counted the same way). A line longer than the terminal is shown
 * as a single-line view scrolled horizontally so the cursor stays visible;
 * the width is queried again on every redraw, so a resize takes effect at
 * the next key.
 *
 * History: entries are single lines, oldest first. lineedit_history_add
 * ignores empty and all-blank lines and a line equal to the newest entry;
 * text containing '\n' is added line by line. At most history_max entries
 * are kept (the oldest are dropped); history_max <= 0 disables history. The
 * file (history_path, may be NULL) holds one entry per line; a missing or
 * unreadable file is not an error. It is written atomically (temporary file
 * + rename) by lineedit_history_save and by lineedit_free when entries were
 * added. While editing, Up/Down walk the history; edits made to a recalled
 * entry are kept until the line is submitted (the stored history is never
 * changed), and moving Down past the newest entry returns to the line that
 * was being typed.
 *
 * Terminal restoration: while a raw-mode read is in progress, handlers for
 * SIGTERM, SIGHUP, SIGQUIT and the fatal signals (SIGSEGV, SIGBUS, SIGFPE,
 * SIGILL, SIGABRT) restore the terminal, reinstate the previous action and
 * re-raise the signal; SIGTSTP (also sent by the Ctrl-Z key) restores the
 * terminal, stops the process and re-enters raw mode and redraws on
 * resume; SIGCONT re-enters raw mode. Signals the process ignores stay
 * ignored. The previous actions are put back when the read returns. An
 * atexit handler restores the terminal too. Ctrl-C is a key in raw mode
 * (ISIG is off), not a signal.
 *
 * Interrupting evaluation: between reads the terminal is in its normal
 * (cooked) mode and Ctrl-C sends SIGINT. lineedit_install_sigint(flag)
 * installs a handler that sets *flag = 1 (with SA_RESTART); a second
 * SIGINT while *flag is still non-zero kills the process with the default
 * action, so a computation that never looks at the flag can still be
 * stopped. lineedit_remove_sigint puts the previous handler back.
 *
 * Not thread-safe: one editor reads at a time (signal handlers need one
 * static record of the terminal being edited).
 */
#ifndef LINEEDIT_H
#define LINEEDIT_H

#include <signal.h>

#include "rt.h"

typedef struct lineedit lineedit;

typedef enum lineedit_result {
    LINEEDIT_LINE = 0,
    LINEEDIT_EOF,
    LINEEDIT_INTERRUPT,
    LINEEDIT_ERROR,
} lineedit_result;

/* Create an editor; NULL only if memory runs out. history_path may be NULL
 * (history kept in memory only). Loads the history file if it exists. */
lineedit *lineedit_new(int in_fd, int out_fd, const char *history_path, int history_max);
/* Read one line; see the results above. prompt may be NULL (no prompt). */
lineedit_result lineedit_read(lineedit *le, const char *prompt, char **line);
/* Add a line to the history (see the rules above). */
void lineedit_history_add(lineedit *le, const char *line);
/* Number of history entries and entry i (0 = oldest), NULL if out of range. */
int lineedit_history_len(const lineedit *le);
const char *lineedit_history_get(const lineedit *le, int i);
/* Write the history file now (atomically). RT_OK if there is no file. */
rt_code lineedit_history_save(lineedit *le, rt_error *e);
/* Save the history if it changed (errors ignored), restore the terminal if
 * needed, free. NULL is allowed. */
void lineedit_free(lineedit *le);

/* 1 in raw (full editing) mode, 0 in dumb or piped mode. */
int lineedit_is_raw(const lineedit *le);
/* Why the last read returned LINEEDIT_ERROR ("" if it did not). */
const char *lineedit_errmsg(const lineedit *le);

/* Columns of the terminal on fd: ioctl TIOCGWINSZ, else the COLUMNS
 * environment variable, else 80. */
int lineedit_term_width(int fd);

/* SIGINT -> *flag = 1 (see above). Returns 0, or -1 if sigaction failed.
 * Installing again replaces the flag; remove restores the action that was
 * in place before the first install. */
int lineedit_install_sigint(volatile sig_atomic_t *flag);
void lineedit_remove_sigint(void);

#endif
