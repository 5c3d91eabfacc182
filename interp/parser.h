/* parser.h — script text to syntax tree.
 *
 * parse_source tokenises and parses source `src` (already added to the
 * state) into an N_BLOCK of statements allocated in the state's arena.
 * On a syntax error it records the error (I->err; err.incomplete is set when
 * the input merely ended too early, which the REPL uses to ask for more).
 */
#ifndef PARSER_H
#define PARSER_H

#include "state.h"

int parse_source(interp *I, int src, node **out);

#endif
