/* The log levels and the logger both FMU cores call (the FMI wrappers pass theirs). */
#ifndef PAM_LOG_H
#define PAM_LOG_H

enum { PAM_LOG_INFO = 0, PAM_LOG_WARNING = 1, PAM_LOG_ERROR = 2 };

typedef void (*PamLogFn)(void *env, int level, const char *message);

#endif
