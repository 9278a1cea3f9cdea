// eamos-peak-rss PROGRAM ARGS...: runs PROGRAM and prints its peak resident memory in KiB
// ("peak_kib N") and its exit status ("status N") on standard output; PROGRAM's own output
// goes to /dev/null. Linux carries the resident size of the process that forks into the
// child's ru_maxrss, so a test forking the measured program itself would measure the test:
// this small C launcher is what forks.
#include <fcntl.h>
#include <stdio.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: eamos-peak-rss PROGRAM ARGS...\n");
    return 2;
  }
  pid_t pid = fork();
  if (pid == 0) {
    int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execv(argv[1], argv + 1);
    _exit(127);
  }
  int status = 0;
  struct rusage usage;
  if (pid < 0 || wait4(pid, &status, 0, &usage) != pid) return 2;
  printf("peak_kib %ld\nstatus %d\n", usage.ru_maxrss, WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
  return 0;
}
