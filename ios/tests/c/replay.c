/*
 * Desktop test of the C ABI (run by ios/tests/c_abi.rs): compiled with a C compiler against the
 * generated include/phantogram.h and linked with the static library the XCFramework packs.
 * Replays a sensor log through the Core Motion entry points exactly as the Swift shell would
 * (g with Core Motion's sign, seconds since boot), draws offscreen every 100 ms of log time and
 * writes the last frame's RGBA bytes. Also checks the error contract (status codes, messages).
 *
 * Usage: replay LOG OUT WIDTH HEIGHT
 */
#include "phantogram.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void check(PgStatus got, PgStatus want, const char *what, const char *fragment) {
    char message[512];
    pg_last_error(message, sizeof message);
    if (got != want || (fragment && !strstr(message, fragment))) {
        fprintf(stderr, "%s: status %d (want %d), message \"%s\" (want \"%s\")\n", what, (int)got, (int)want,
                message, fragment ? fragment : "");
        exit(1);
    }
    if (fragment) {
        printf("ok: %s -> %d: %s\n", what, (int)got, message);
    }
}

int main(int argc, char **argv) {
    if (argc != 5) {
        fprintf(stderr, "usage: replay LOG OUT WIDTH HEIGHT\n");
        return 2;
    }
    const char *log_path = argv[1];
    const char *out_path = argv[2];
    uint32_t width = (uint32_t)atoi(argv[3]);
    uint32_t height = (uint32_t)atoi(argv[4]);

    /* The error contract. */
    check(pg_draw(NULL, 0.0, NULL), PG_STATUS_NULL_POINTER, "pg_draw(NULL)", "null");
    PgConfig config = pg_config_default();
    config.anaglyph = "sepia";
    PgEngine *engine = (PgEngine *)1;
    check(pg_engine_create(&config, &engine), PG_STATUS_INVALID_ARGUMENT, "create with anaglyph sepia", "sepia");
    if (engine != NULL) {
        fprintf(stderr, "a failed create must leave the handle null\n");
        return 1;
    }
    config.anaglyph = "dubois";
    config.rotation_quarter_turns = 5;
    check(pg_engine_create(&config, &engine), PG_STATUS_INVALID_ARGUMENT, "create with rotation 5", "rotation");
    config.rotation_quarter_turns = 0;
    check(pg_engine_create(&config, &engine), PG_STATUS_OK, "create", NULL);
    if (pg_last_error(NULL, 0) != 1) {
        fprintf(stderr, "success must clear the error message\n");
        return 1;
    }
    uint32_t w = 0, h = 0;
    check(pg_read_frame(engine, NULL, 0, &w, &h), PG_STATUS_NO_FRAME, "read before drawing", "no offscreen frame");
    check(pg_resume_view(engine, NULL, 10, 10), PG_STATUS_NULL_POINTER, "resume a null view", "ui_view");
    check(pg_set_anaglyph(engine, "sepia"), PG_STATUS_INVALID_ARGUMENT, "set anaglyph sepia", "sepia");
    check(pg_set_sensor_ranges(NULL, 78.4532f, 34.906586f), PG_STATUS_NULL_POINTER, "sensor ranges on null", "null");
    check(pg_set_sensor_ranges(engine, 78.4532f, 34.906586f), PG_STATUS_OK, "sensor ranges", NULL);
    uint8_t presented = 9;
    check(pg_draw(engine, -1.0, &presented), PG_STATUS_OK, "draw while suspended", NULL);
    if (presented != 0) {
        fprintf(stderr, "drawing without a target must be a skipped frame\n");
        return 1;
    }
    check(pg_resume_offscreen(engine, width, height), PG_STATUS_OK, "resume offscreen", NULL);

    FILE *log = fopen(log_path, "r");
    if (!log) {
        perror(log_path);
        return 1;
    }
    const double g = STANDARD_GRAVITY_M_S2;
    const long long step_ns = 100000000LL;
    long long next = 0, last = 0;
    int have_next = 0, frames = 0, rejected = 0;
    char line[256];
    while (fgets(line, sizeof line, log)) {
        char kind[8];
        long long t;
        double x, y, z;
        if (sscanf(line, "%7s %lld %lf %lf %lf", kind, &t, &x, &y, &z) != 5) {
            continue;
        }
        int which = strcmp(kind, "acc") == 0 ? 1 : strcmp(kind, "gyr") == 0 ? 2 : strcmp(kind, "mag") == 0 ? 3 : 0;
        if (!which) {
            continue;
        }
        if (!have_next) {
            next = t + step_ns;
            have_next = 1;
        }
        while (t > next) {
            check(pg_draw(engine, (double)next * 1e-9, &presented), PG_STATUS_OK, "draw", NULL);
            frames += presented;
            next += step_ns;
        }
        double t_s = (double)t * 1e-9;
        PgStatus s;
        if (which == 1) {
            /* Core Motion reports acceleration in g, with gravity negative when face up. */
            s = pg_push_accelerometer(engine, t_s, -x / g, -y / g, -z / g);
        } else if (which == 2) {
            s = pg_push_gyroscope(engine, t_s, x, y, z);
        } else {
            s = pg_push_magnetometer(engine, t_s, x, y, z);
        }
        if (s == PG_STATUS_REJECTED) {
            rejected++;
        } else {
            check(s, PG_STATUS_OK, "push", NULL);
        }
        last = t;
    }
    fclose(log);
    check(pg_draw(engine, (double)last * 1e-9, &presented), PG_STATUS_OK, "last draw", NULL);
    frames += presented;

    check(pg_read_frame(engine, NULL, 0, &w, &h), PG_STATUS_OK, "frame size", NULL);
    if (w != width || h != height) {
        fprintf(stderr, "frame is %ux%u, want %ux%u\n", w, h, width, height);
        return 1;
    }
    size_t size = (size_t)w * h * 4;
    uint8_t *pixels = malloc(size);
    check(pg_read_frame(engine, pixels, size - 1, &w, &h), PG_STATUS_BUFFER_TOO_SMALL, "short buffer", "needs");
    check(pg_read_frame(engine, pixels, size, &w, &h), PG_STATUS_OK, "read frame", NULL);
    FILE *out = fopen(out_path, "wb");
    if (!out || fwrite(pixels, 1, size, out) != size) {
        perror(out_path);
        return 1;
    }
    fclose(out);
    free(pixels);

    /* The rest of the ABI once: touch, display, camera (face tracking off), lifecycle. */
    int gesture = -1;
    check(pg_touch(engine, 0, 0, 10.0f, 10.0f, (double)last * 1e-9, &gesture), PG_STATUS_OK, "touch down", NULL);
    check(pg_touch(engine, 7, 0, 10.0f, 10.0f, (double)last * 1e-9, &gesture), PG_STATUS_INVALID_ARGUMENT,
          "touch phase 7", "touch phase");
    check(pg_set_display(engine, 1080, 2400, 420.0f, 420.0f, 0), PG_STATUS_OK, "set display", NULL);
    uint8_t luma[64 * 48] = {0};
    uint8_t cbcr[64 * 24] = {0};
    double t = (double)last * 1e-9;
    check(pg_camera_frame(engine, 0, luma, 64, 48, 64, NULL, 0, 270, 50.0f, 50.0f, 32.0f, 24.0f, NAN, NAN, NAN, t),
          PG_STATUS_UNSUPPORTED, "camera frame without face tracking", "face tracking is off");
    check(pg_camera_frame(engine, 0, luma, 64, 48, 64, cbcr, 64, 270, 50.0f, 50.0f, 32.0f, 24.0f, 0.01, 200.0, 2.2, t),
          PG_STATUS_UNSUPPORTED, "colour camera frame without face tracking", "face tracking is off");
    check(pg_camera_frame(engine, 0, luma, 64, 48, 64, NULL, 0, 45, 50.0f, 50.0f, 32.0f, 24.0f, NAN, NAN, NAN, t),
          PG_STATUS_INVALID_ARGUMENT, "camera frame turned 45 degrees", "rotation");
    check(pg_camera_frame(engine, 0, luma, 64, 48, 64, cbcr, 32, 270, 50.0f, 50.0f, 32.0f, 24.0f, NAN, NAN, NAN, t),
          PG_STATUS_INVALID_ARGUMENT, "CbCr rows narrower than the frame", "Cb row stride");
    /* The rear camera feeds the room light alone, off in this engine; cameras are 0 or 1. */
    check(pg_camera_frame(engine, 1, luma, 64, 48, 64, cbcr, 64, 90, 50.0f, 50.0f, 32.0f, 24.0f, 0.01, 200.0, 1.8, t),
          PG_STATUS_UNSUPPORTED, "rear camera frame without the room light", "room light is off");
    check(pg_camera_frame(engine, 2, luma, 64, 48, 64, NULL, 0, 90, 50.0f, 50.0f, 32.0f, 24.0f, NAN, NAN, NAN, t),
          PG_STATUS_INVALID_ARGUMENT, "a third camera", "camera must be 0");
    check(pg_resize(engine, width / 2, height / 2), PG_STATUS_OK, "resize", NULL);
    check(pg_suspend(engine), PG_STATUS_OK, "suspend", NULL);
    size_t needed = 0;
    check(pg_calibration_warning(engine, NULL, 0, &needed), PG_STATUS_OK, "calibration warning", NULL);
    if (needed != 1) {
        fprintf(stderr, "no calibration file, yet a calibration warning of %zu bytes\n", needed);
        return 1;
    }
    check(pg_calibration_warning(engine, NULL, 0, NULL), PG_STATUS_NULL_POINTER, "calibration warning to null",
          "needed");
    PgStats stats;
    check(pg_stats(engine, &stats), PG_STATUS_OK, "stats", NULL);
    printf("frames %d drawn %llu skipped %llu accepted %llu rejected %llu (driver saw %d)\n", frames,
           (unsigned long long)stats.frames_drawn, (unsigned long long)stats.frames_skipped,
           (unsigned long long)stats.sensor_events_accepted, (unsigned long long)stats.sensor_events_rejected,
           rejected);
    pg_engine_destroy(engine);
    pg_engine_destroy(NULL);

    /* A damaged calibration file: the engine starts with the defaults and says why. */
    char calibration_path[4096];
    snprintf(calibration_path, sizeof calibration_path, "%s.calibration.txt", out_path);
    FILE *damaged = fopen(calibration_path, "w");
    if (!damaged) {
        fprintf(stderr, "cannot write %s\n", calibration_path);
        return 1;
    }
    fputs("not a calibration\n", damaged);
    fclose(damaged);
    config = pg_config_default();
    config.calibration_path = calibration_path;
    check(pg_engine_create(&config, &engine), PG_STATUS_OK, "create with a damaged calibration file", NULL);
    char warning[8] = {0};
    check(pg_calibration_warning(engine, warning, sizeof warning, &needed), PG_STATUS_OK, "calibration warning",
          NULL);
    char *whole = malloc(needed);
    check(pg_calibration_warning(engine, whole, needed, &needed), PG_STATUS_OK, "calibration warning", NULL);
    if (needed <= sizeof warning || strlen(warning) != sizeof warning - 1 || !strstr(whole, ".calibration.txt")) {
        fprintf(stderr, "calibration warning: %zu bytes, \"%s\" / \"%s\"\n", needed, warning, whole);
        return 1;
    }
    printf("ok: damaged calibration file -> \"%s\"\n", whole);
    free(whole);
    pg_engine_destroy(engine);

    /* The artifact library as the Swift shell uses it: start on a saved artifact, open a file,
     * choose another, share the view. Loads run in the background: draw until they end. */
    char library_dir[4096];
    snprintf(library_dir, sizeof library_dir, "%s.library", out_path);
    config = pg_config_default();
    config.library_dir = library_dir;
    config.artifact = "builtin:medal";
    check(pg_engine_create(&config, &engine), PG_STATUS_OK, "create on the medal", NULL);
    char id[64] = {0};
    if (pg_current_artifact(engine, id, sizeof id) != strlen("builtin:medal") + 1 || strcmp(id, "builtin:medal")) {
        fprintf(stderr, "current artifact \"%s\", want builtin:medal\n", id);
        return 1;
    }
    check(pg_select_artifact(engine, "medal"), PG_STATUS_INVALID_ARGUMENT, "select a bare name", "artifact id");
    check(pg_import_artifact(engine, "empty.glb", NULL, 0), PG_STATUS_INVALID_ARGUMENT, "import nothing", "empty");
    check(pg_resume_offscreen(engine, 90, 200), PG_STATUS_OK, "resume offscreen", NULL);
    static const uint8_t damaged_glb[] = "glTF\x02\0\0\0 not really a model";
    check(pg_import_artifact(engine, "damaged.glb", damaged_glb, sizeof damaged_glb), PG_STATUS_OK, "import", NULL);
    int state = 1;
    float fraction = 0.0f;
    for (int i = 0; i < 100000 && state == 1; i++) {
        check(pg_draw(engine, -1.0, NULL), PG_STATUS_OK, "draw while importing", NULL);
        check(pg_loading_state(engine, &state, &fraction), PG_STATUS_OK, "loading state", NULL);
    }
    if (state != 2) {
        fprintf(stderr, "a damaged file ended in loading state %d, want 2 (failed)\n", state);
        return 1;
    }
    check(pg_select_artifact(engine, "builtin:tablet"), PG_STATUS_OK, "select the tablet", NULL);
    for (int i = 0; i < 100000 && state != 0; i++) {
        check(pg_draw(engine, -1.0, NULL), PG_STATUS_OK, "draw while loading", NULL);
        check(pg_loading_state(engine, &state, NULL), PG_STATUS_OK, "loading state", NULL);
    }
    check(pg_draw(engine, -1.0, NULL), PG_STATUS_OK, "draw the tablet", NULL);
    pg_current_artifact(engine, id, sizeof id);
    if (state != 0 || strcmp(id, "builtin:tablet")) {
        fprintf(stderr, "after selecting the tablet: state %d, on screen \"%s\"\n", state, id);
        return 1;
    }
    check(pg_open_menu(engine), PG_STATUS_OK, "open the menu", NULL);
    check(pg_set_text_scale(engine, 1.3f), PG_STATUS_OK, "text scale", NULL);
    check(pg_set_text_scale(engine, 0.0f), PG_STATUS_INVALID_ARGUMENT, "text scale 0", "text scale");
    /* The core explains the camera before anything is asked of the system. */
    check(pg_camera_permission_needed(engine), PG_STATUS_OK, "camera permission needed", NULL);
    check(pg_camera_permission_needed(NULL), PG_STATUS_NULL_POINTER, "camera permission on null", "engine");
    check(pg_draw(engine, -1.0, NULL), PG_STATUS_OK, "draw with the camera page waiting", NULL);
    int request = -1;
    check(pg_take_shell_request(engine, &request), PG_STATUS_OK, "shell request", NULL);
    check(pg_take_shell_request(engine, NULL), PG_STATUS_NULL_POINTER, "shell request to null", "request");
    if (request != 0) {
        fprintf(stderr, "shell request %d before anything was asked\n", request);
        return 1;
    }
    size_t png_len = 0;
    check(pg_snapshot_png(engine, 5, NULL, 0, &png_len), PG_STATUS_INVALID_ARGUMENT, "snapshot kind 5", "kind");
    check(pg_snapshot_png(engine, 1, NULL, 0, &png_len), PG_STATUS_OK, "side-by-side size", NULL);
    uint8_t *png = malloc(png_len);
    check(pg_snapshot_png(engine, 1, png, png_len - 1, &png_len), PG_STATUS_BUFFER_TOO_SMALL, "short buffer", "needs");
    check(pg_snapshot_png(engine, 1, png, png_len, &png_len), PG_STATUS_OK, "side-by-side picture", NULL);
    /* A PNG 180 pixels wide (two eyes of 90) and 200 high: the IHDR chunk's big-endian sizes. */
    uint32_t png_w = (uint32_t)png[16] << 24 | (uint32_t)png[17] << 16 | (uint32_t)png[18] << 8 | png[19];
    uint32_t png_h = (uint32_t)png[20] << 24 | (uint32_t)png[21] << 16 | (uint32_t)png[22] << 8 | png[23];
    if (memcmp(png + 1, "PNG", 3) || png_w != 180 || png_h != 200) {
        fprintf(stderr, "side-by-side PNG: %ux%u\n", png_w, png_h);
        return 1;
    }
    free(png);
    printf("ok: library: damaged import reported, tablet shown, side-by-side PNG %zu bytes\n", png_len);

    /* What VoiceOver is given: the menu's nodes, each named and placed; "Done" activated moves
       the screens on (the generation says so). */
    check(pg_draw(engine, -1.0, NULL), PG_STATUS_OK, "draw the menu", NULL);
    PgAccessSnapshot *snapshot = NULL;
    uint64_t generation = 0, later = 0;
    check(pg_accessibility_snapshot(engine, NULL, NULL), PG_STATUS_NULL_POINTER, "snapshot to null", "out");
    check(pg_accessibility_snapshot(engine, &snapshot, &generation), PG_STATUS_OK, "accessibility snapshot", NULL);
    size_t count = pg_access_snapshot_len(snapshot);
    int done_id = -1;
    for (size_t i = 0; i < count; i++) {
        PgAccessNode node;
        check(pg_access_snapshot_node(snapshot, i, &node), PG_STATUS_OK, "accessibility node", NULL);
        if (!node.label || !node.label[0] || !(node.right > node.left) || !(node.bottom > node.top) || node.id <= 0) {
            fprintf(stderr, "node %zu without a name or a place\n", i);
            return 1;
        }
        if (node.role == 1 && (node.flags & 1) && !strcmp(node.label, "Done")) {
            done_id = node.id;
        }
    }
    PgAccessNode beyond;
    check(pg_access_snapshot_node(snapshot, count, &beyond), PG_STATUS_INVALID_ARGUMENT, "node past the end", "node");
    pg_access_snapshot_free(snapshot);
    pg_access_snapshot_free(NULL);
    if (count < 5 || done_id < 0) {
        fprintf(stderr, "%zu accessibility nodes, \"Done\" %s\n", count, done_id < 0 ? "missing" : "found");
        return 1;
    }
    uint8_t acted = 1;
    check(pg_accessibility_click(engine, 99999, &acted), PG_STATUS_OK, "activate an unknown node", NULL);
    if (acted) {
        fprintf(stderr, "an unknown node was activated\n");
        return 1;
    }
    check(pg_accessibility_adjust(engine, done_id, 1, &acted), PG_STATUS_OK, "step a button", NULL);
    if (acted) {
        fprintf(stderr, "a button was stepped like a slider\n");
        return 1;
    }
    check(pg_accessibility_click(engine, done_id, &acted), PG_STATUS_OK, "activate Done", NULL);
    check(pg_draw(engine, -1.0, NULL), PG_STATUS_OK, "draw after Done", NULL);
    check(pg_draw(engine, -1.0, NULL), PG_STATUS_OK, "draw after Done", NULL);
    check(pg_accessibility_generation(engine, &later), PG_STATUS_OK, "generation", NULL);
    if (!acted || later == generation) {
        fprintf(stderr, "activating Done changed nothing (acted %d)\n", acted);
        return 1;
    }
    printf("ok: accessibility: %zu nodes read, Done activated\n", count);
    pg_engine_destroy(engine);
    printf("done\n");
    return 0;
}
