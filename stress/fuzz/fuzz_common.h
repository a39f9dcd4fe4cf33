/* fuzz_common.h — what the libFuzzer harnesses of stress/fuzz share: the
 * readers take a path, so each input is written to a private scratch file
 * first (one per process, under $TMPDIR or /tmp). */
#ifndef FUZZ_COMMON_H
#define FUZZ_COMMON_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A private folder for this process's scratch files (made once). */
static const char *fuzz_dir(void)
{
    static char dir[512];
    if (!dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(dir, sizeof dir, "%s/pound-fuzz-XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(dir)) {
            perror("mkdtemp");
            abort();
        }
    }
    return dir;
}

/* Write data to DIR/name; the path in path (cap bytes). */
static void fuzz_write(const char *name, const uint8_t *data, size_t size, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", fuzz_dir(), name);
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        abort();
    }
    if (size && fwrite(data, 1, size, f) != size) {
        perror(path);
        abort();
    }
    fclose(f);
}

/* The key line of a journal input that starts with magic ("...\nkey ")
 * into key (cap bytes), so that the reader gets past its header check;
 * key is left as it is when the input has none.  Its length, or 0. */
static size_t fuzz_key(const uint8_t *data, size_t size, const char *magic, char *key, size_t cap)
{
    size_t lm = strlen(magic);
    if (size <= lm || memcmp(data, magic, lm))
        return 0;
    const uint8_t *k = data + lm, *nl = memchr(k, '\n', size - lm);
    size_t len = nl ? (size_t)(nl - k) : 0;
    if (!nl || len == 0 || len >= cap || memchr(k, '\0', len))
        return 0;
    memcpy(key, k, len);
    key[len] = '\0';
    return len;
}

#endif
