!> The processes a simulation runs on: a communicator value and the collective operations the
!> solver needs (sums of nodal fields, global minima and maxima, agreement on a failure,
!> gathering particle rows on the root). Built with `-DEMPM_USE_MPI=ON` it wraps an `mpi_f08`
!> communicator (a duplicate of the one it is made from, so empm's messages never meet the
!> host's); otherwise, and for a communicator of one process, every operation is the identity
!> and costs nothing. No global state: whoever makes the value owns it (docs/parallel.md).
module empm_comm
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, EMPM_OK
#ifdef EMPM_USE_MPI
  use mpi_f08, only: MPI_Comm, MPI_COMM_WORLD, MPI_COMM_NULL, MPI_Init, MPI_Initialized, &
    MPI_Finalize, MPI_Finalized, MPI_Comm_rank, MPI_Comm_size, MPI_Comm_dup, MPI_Comm_free, &
    MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_LOGICAL, MPI_SUM, &
    MPI_Op, MPI_MAX, MPI_MIN, MPI_LOR, MPI_Bcast, MPI_Alltoall, MPI_Alltoallv, MPI_CHARACTER, &
    MPI_Gather, MPI_Gatherv, MPI_Barrier, MPI_Allgather, MPI_Allgatherv, MPI_Request, &
    MPI_Isend, MPI_Irecv, MPI_Comm_split_type, MPI_COMM_TYPE_SHARED, MPI_INFO_NULL, &
    MPI_Waitall, MPI_STATUSES_IGNORE, MPI_Abort, operator(/=)
#endif
  implicit none
  private
  public :: empm_comm_t, empm_comm_world, empm_comm_serial, empm_comm_from_handle, &
            empm_comm_handle_problem, EMPM_MPI_BUILT

#ifdef EMPM_USE_MPI
  logical, parameter :: EMPM_MPI_BUILT = .true.  !! this build can run on several processes
#else
  logical, parameter :: EMPM_MPI_BUILT = .false. !! this build can run on several processes
#endif
  integer, parameter :: OP_SUM = 1, OP_MAX = 2, OP_MIN = 3 ! reductions

  !> A group of processes running one simulation together (one process: serial).
  type :: empm_comm_t
    integer :: rank = 0            !! this process, 0 .. nranks − 1
    integer :: nranks = 1          !! number of processes
    logical :: owns_mpi = .false.  !! this value started MPI (its `finish` ends it)
#ifdef EMPM_USE_MPI
    type(MPI_Comm) :: handle = MPI_COMM_NULL !! private duplicate (null: serial)
#endif
  contains
    procedure :: is_root => comm_is_root
    procedure :: parallel => comm_parallel
    procedure, private :: sum_r1, sum_r2, sum_r3
    generic :: sum => sum_r1, sum_r2, sum_r3
    procedure :: sum_real => comm_sum_real
    procedure :: max_real => comm_max_real
    procedure :: min_real => comm_min_real
    procedure :: sum_int => comm_sum_int
    procedure :: sum_counts => comm_sum_counts
    procedure :: max_reals => comm_max_reals
    procedure :: max_int => comm_max_int
    procedure :: min_int => comm_min_int
    procedure :: bcast_ints => comm_bcast_ints
    procedure :: any_true => comm_any_true
    procedure :: bcast_text => comm_bcast_text
    procedure :: agree => comm_agree
    procedure :: machine_size => comm_machine_size
    procedure :: gather_rows => comm_gather_rows
    procedure :: exchange_rows => comm_exchange_rows
    procedure :: allgather_ints => comm_allgather_ints
    procedure :: swap => comm_swap
    procedure :: barrier => comm_barrier
    procedure :: abort => comm_abort
    procedure :: finish => comm_finish
  end type empm_comm_t

contains

  !> One process, no MPI: what every library call uses unless given another communicator.
  pure function empm_comm_serial() result(comm)
    type(empm_comm_t) :: comm !! rank 0 of 1
    comm%rank = 0; comm%nranks = 1
  end function empm_comm_serial

  !> All the processes the program was started on (`mpirun -n N`), starting MPI when nobody has
  !> yet (then [[empm_comm_t:finish]] ends it). Serial without MPI in the build, and for a
  !> program not started by a launcher (no launcher variable in the environment: Open MPI's
  !> OMPI_COMM_WORLD_SIZE, PMIx's PMIX_RANK, PMI's PMI_SIZE): MPI_Init would start a singleton
  !> runtime, which needs resources (shared memory, files) a plain run must not.
  function empm_comm_world() result(comm)
    type(empm_comm_t) :: comm !! the processes of the run
#ifdef EMPM_USE_MPI
    logical :: up
    call MPI_Initialized(up)
    if (.not. up) then
      if (.not. launched()) then
        comm = empm_comm_serial()
        return
      end if
      call MPI_Init()
      comm%owns_mpi = .true.
    end if
    call MPI_Comm_dup(MPI_COMM_WORLD, comm%handle)
    call MPI_Comm_rank(comm%handle, comm%rank)
    call MPI_Comm_size(comm%handle, comm%nranks)
#else
    comm = empm_comm_serial()
#endif
  end function empm_comm_world

  !> The processes of a host's communicator, given by its Fortran handle: `MPI_Comm_c2f(comm)`
  !> in C, the INTEGER communicator of `mpif.h` or the `mpi` module, `comm%MPI_VAL` of
  !> `mpi_f08`. empm works on a private duplicate (its messages never meet the host's), which
  !> [[empm_comm_t:finish]] frees; MPI stays the host's to end. `info`: 0, or what
  !> [[empm_comm_handle_problem]] explains (the result is then serial).
  subroutine empm_comm_from_handle(handle, comm, info)
    integer, intent(in) :: handle            !! the host's communicator (Fortran handle)
    type(empm_comm_t), intent(out) :: comm   !! its processes
    integer, intent(out) :: info             !! 0; 1 no MPI in this build; 2 MPI not started;
                                             !! 3 MPI_COMM_NULL
#ifdef EMPM_USE_MPI
    type(MPI_Comm) :: host
    logical :: up
    comm = empm_comm_serial()
    call MPI_Initialized(up)
    if (.not. up) then
      info = 2; return
    end if
    if (handle == MPI_COMM_NULL%MPI_VAL) then
      info = 3; return
    end if
    info = 0
    host%MPI_VAL = handle
    call MPI_Comm_dup(host, comm%handle)
    call MPI_Comm_rank(comm%handle, comm%rank)
    call MPI_Comm_size(comm%handle, comm%nranks)
#else
    associate (unused => handle); end associate
    comm = empm_comm_serial()
    info = 1
#endif
  end subroutine empm_comm_from_handle

  !> What a status of [[empm_comm_from_handle]] means ('' for 0).
  pure function empm_comm_handle_problem(info) result(text)
    integer, intent(in) :: info             !! status
    character(len=:), allocatable :: text   !! explanation
    select case (info)
    case (0); text = ''
    case (1); text = 'this empm was built without MPI (configure with -DEMPM_USE_MPI=ON)'
    case (2); text = 'MPI is not initialized: call MPI_Init before handing empm a communicator'
    case (3); text = 'the communicator is MPI_COMM_NULL'
    case default; text = 'unknown communicator status'
    end select
  end function empm_comm_handle_problem

#ifdef EMPM_USE_MPI
  ! A process launcher (mpirun, mpiexec, srun) started this program.
  logical function launched()
    character(len=*), parameter :: VARS(3) = [character(len=20) :: 'OMPI_COMM_WORLD_SIZE', &
                                              'PMIX_RANK', 'PMI_SIZE']
    integer :: k, n, st
    launched = .false.
    do k = 1, size(VARS)
      call get_environment_variable(trim(VARS(k)), length=n, status=st)
      if (st == 0 .and. n > 0) launched = .true.
    end do
  end function launched
#endif

  !> .true. on rank 0, which reads alone, writes the files and prints.
  elemental logical function comm_is_root(self)
    class(empm_comm_t), intent(in) :: self !! communicator
    comm_is_root = self%rank == 0
  end function comm_is_root

  !> .true. when more than one process shares the run.
  elemental logical function comm_parallel(self)
    class(empm_comm_t), intent(in) :: self !! communicator
    comm_parallel = self%nranks > 1
  end function comm_parallel

  !> a ← Σ over the processes of a (every process gets the sum).
  subroutine sum_r1(self, a)
    class(empm_comm_t), intent(in) :: self           !! communicator
    real(wp), intent(inout), contiguous :: a(:)      !! values, summed in place
    call sum_buffer(self, a, size(a))
  end subroutine sum_r1

  !> a ← Σ over the processes of a (nodal fields: (ndim, nnode)).
  subroutine sum_r2(self, a)
    class(empm_comm_t), intent(in) :: self           !! communicator
    real(wp), intent(inout), contiguous :: a(:,:)    !! values, summed in place
    call sum_buffer(self, a, size(a))
  end subroutine sum_r2

  !> a ← Σ over the processes of a.
  subroutine sum_r3(self, a)
    class(empm_comm_t), intent(in) :: self           !! communicator
    real(wp), intent(inout), contiguous :: a(:,:,:)  !! values, summed in place
    call sum_buffer(self, a, size(a))
  end subroutine sum_r3

  ! The n values of a contiguous array of any rank (sequence association), summed in place.
  subroutine sum_buffer(self, a, n)
    class(empm_comm_t), intent(in) :: self
    integer, intent(in) :: n
    real(wp), intent(inout) :: a(n)
    if (self%nranks <= 1 .or. size(a) == 0) return
#ifdef EMPM_USE_MPI
    call MPI_Allreduce(MPI_IN_PLACE, a, n, MPI_DOUBLE_PRECISION, MPI_SUM, self%handle)
#endif
  end subroutine sum_buffer

  !> c ← Σ over the processes of c (integer counts, every process gets the sum).
  subroutine comm_sum_counts(self, c)
    class(empm_comm_t), intent(in) :: self      !! communicator
    integer, intent(inout), contiguous :: c(:)  !! counts, summed in place
    if (self%nranks <= 1 .or. size(c) == 0) return
#ifdef EMPM_USE_MPI
    call MPI_Allreduce(MPI_IN_PLACE, c, size(c), MPI_INTEGER, MPI_SUM, self%handle)
#endif
  end subroutine comm_sum_counts

  !> a ← the largest value over the processes, entry by entry (every process gets it).
  subroutine comm_max_reals(self, a)
    class(empm_comm_t), intent(in) :: self      !! communicator
    real(wp), intent(inout), contiguous :: a(:) !! values, maximised in place
    if (self%nranks <= 1 .or. size(a) == 0) return
#ifdef EMPM_USE_MPI
    call MPI_Allreduce(MPI_IN_PLACE, a, size(a), MPI_DOUBLE_PRECISION, MPI_MAX, self%handle)
#endif
  end subroutine comm_max_reals

  !> Σ over the processes of x.
  function comm_sum_real(self, x) result(s)
    class(empm_comm_t), intent(in) :: self !! communicator
    real(wp), intent(in) :: x              !! this process's value
    real(wp) :: s                          !! the sum
    s = reduce_real(self, x, OP_SUM)
  end function comm_sum_real

  !> Largest x over the processes.
  function comm_max_real(self, x) result(s)
    class(empm_comm_t), intent(in) :: self !! communicator
    real(wp), intent(in) :: x              !! this process's value
    real(wp) :: s                          !! the maximum
    s = reduce_real(self, x, OP_MAX)
  end function comm_max_real

  !> Smallest x over the processes.
  function comm_min_real(self, x) result(s)
    class(empm_comm_t), intent(in) :: self !! communicator
    real(wp), intent(in) :: x              !! this process's value
    real(wp) :: s                          !! the minimum
    s = reduce_real(self, x, OP_MIN)
  end function comm_min_real

  !> Σ over the processes of i.
  function comm_sum_int(self, i) result(s)
    class(empm_comm_t), intent(in) :: self !! communicator
    integer, intent(in) :: i               !! this process's value
    integer :: s                           !! the sum
    s = reduce_int(self, i, OP_SUM)
  end function comm_sum_int

  !> Largest i over the processes (agreeing on a status: every process takes the worst).
  function comm_max_int(self, i) result(s)
    class(empm_comm_t), intent(in) :: self !! communicator
    integer, intent(in) :: i               !! this process's value
    integer :: s                           !! the maximum
    s = reduce_int(self, i, OP_MAX)
  end function comm_max_int

  !> Smallest i over the processes.
  function comm_min_int(self, i) result(s)
    class(empm_comm_t), intent(in) :: self !! communicator
    integer, intent(in) :: i               !! this process's value
    integer :: s                           !! the minimum
    s = reduce_int(self, i, OP_MIN)
  end function comm_min_int

  ! x reduced over the processes by OP_SUM, OP_MAX or OP_MIN.
  function reduce_real(self, x, op) result(s)
    class(empm_comm_t), intent(in) :: self
    real(wp), intent(in) :: x
    integer, intent(in) :: op
    real(wp) :: s
    s = x
    if (self%nranks <= 1 .or. op < 0) return
#ifdef EMPM_USE_MPI
    call MPI_Allreduce(x, s, 1, MPI_DOUBLE_PRECISION, op_of(op), self%handle)
#endif
  end function reduce_real

  ! i reduced over the processes by OP_SUM, OP_MAX or OP_MIN.
  function reduce_int(self, i, op) result(s)
    class(empm_comm_t), intent(in) :: self
    integer, intent(in) :: i
    integer, intent(in) :: op
    integer :: s
    s = i
    if (self%nranks <= 1 .or. op < 0) return
#ifdef EMPM_USE_MPI
    call MPI_Allreduce(i, s, 1, MPI_INTEGER, op_of(op), self%handle)
#endif
  end function reduce_int

#ifdef EMPM_USE_MPI
  ! The MPI operation of OP_SUM, OP_MAX, OP_MIN.
  function op_of(op) result(o)
    integer, intent(in) :: op
    type(MPI_Op) :: o
    select case (op)
    case (OP_MAX); o = MPI_MAX
    case (OP_MIN); o = MPI_MIN
    case default; o = MPI_SUM
    end select
  end function op_of
#endif

  !> Every process gets process `from`'s values of a.
  subroutine comm_bcast_ints(self, a, from)
    class(empm_comm_t), intent(in) :: self   !! communicator
    integer, intent(inout) :: a(:)           !! from's values in, everyone's out
    integer, intent(in) :: from              !! the process that has them
    if (self%nranks <= 1 .or. size(a) == 0 .or. from < 0) return
#ifdef EMPM_USE_MPI
    call MPI_Bcast(a, size(a), MPI_INTEGER, from, self%handle)
#endif
  end subroutine comm_bcast_ints

  !> .true. on every process when it is on any.
  function comm_any_true(self, l) result(s)
    class(empm_comm_t), intent(in) :: self !! communicator
    logical, intent(in) :: l               !! this process's value
    logical :: s                           !! l on any process
    s = l
    if (self%nranks <= 1) return
#ifdef EMPM_USE_MPI
    call MPI_Allreduce(l, s, 1, MPI_LOGICAL, MPI_LOR, self%handle)
#endif
  end function comm_any_true

  !> Every process gets process `from`'s text (a message found on one process only).
  subroutine comm_bcast_text(self, text, from)
    class(empm_comm_t), intent(in) :: self                  !! communicator
    character(len=:), allocatable, intent(inout) :: text    !! from's text in, everyone's out
    integer, intent(in) :: from                             !! the process that has it
    integer :: n
    if (self%nranks <= 1) return
    n = 0
    if (self%rank == from) n = len(text)
#ifdef EMPM_USE_MPI
    call MPI_Bcast(n, 1, MPI_INTEGER, from, self%handle)
    if (self%rank /= from) then
      if (allocated(text)) deallocate(text)
      allocate(character(len=n) :: text)
    end if
    if (n > 0) call MPI_Bcast(text, n, MPI_CHARACTER, from, self%handle)
#endif
  end subroutine comm_bcast_text

  !> The number of processes of this communicator that share this process's machine (its
  !> memory): MPI's shared-memory split. Collective; 1 without MPI.
  integer function comm_machine_size(self) result(k)
    class(empm_comm_t), intent(in) :: self     !! communicator
#ifdef EMPM_USE_MPI
    type(MPI_Comm) :: local
#endif
    k = 1
    if (self%nranks <= 1) return
#ifdef EMPM_USE_MPI
    call MPI_Comm_split_type(self%handle, MPI_COMM_TYPE_SHARED, self%rank, MPI_INFO_NULL, local)
    call MPI_Comm_size(local, k)
    call MPI_Comm_free(local)
#endif
  end function comm_machine_size

  !> Every process takes the error of the first process that has one (or none): so that all
  !> stop together, where one alone (a file missing on its machine) would leave the others
  !> waiting in the next collective. Collective.
  subroutine comm_agree(self, e)
    class(empm_comm_t), intent(in) :: self     !! communicator
    type(empm_error_t), intent(inout) :: e     !! this process's outcome in, the first one out
    integer :: first, v(1)
    character(len=:), allocatable :: text
    if (self%nranks <= 1) return
    first = self%min_int(merge(self%rank, self%nranks, e%code /= EMPM_OK))
    if (first == self%nranks) return
    v(1) = e%code
    call self%bcast_ints(v, first)
    text = ''
    if (self%rank == first) text = e%message
    call self%bcast_text(text, first)
    if (self%rank /= first) then
      e%code = v(1); e%message = text
    end if
  end subroutine comm_agree

  !> The root gets every process's rows, process by process: rows(:, 1:n) here, all(:, :) on
  !> the root (allocated there with the total count of columns; elsewhere size 0). With
  !> `to_all`, every process gets them (for short lists: a surface's particles, not a body's).
  subroutine comm_gather_rows(self, rows, n, all, to_all)
    class(empm_comm_t), intent(in) :: self                  !! communicator
    real(wp), intent(in), contiguous :: rows(:,:)           !! this process's rows (m, >= n)
    integer, intent(in) :: n                                !! its number of columns
    real(wp), allocatable, intent(out) :: all(:,:)          !! the root's (m, Σ n)
    logical, intent(in), optional :: to_all                 !! every process gets all(:, :)
    integer :: m
#ifdef EMPM_USE_MPI
    integer, allocatable :: counts(:), displs(:)
    integer :: k
    logical :: everyone
#endif
    m = size(rows, 1)
    if (self%nranks <= 1) then
      allocate(all(m, n))
      all = rows(:, 1:n)
      return
    end if
#ifdef EMPM_USE_MPI
    everyone = .false.
    if (present(to_all)) everyone = to_all
    allocate(counts(self%nranks), displs(self%nranks))
    if (everyone) then
      call MPI_Allgather(m * n, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, self%handle)
    else
      call MPI_Gather(m * n, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, 0, self%handle)
    end if
    if (self%rank == 0 .or. everyone) then
      displs(1) = 0
      do k = 2, self%nranks
        displs(k) = displs(k - 1) + counts(k - 1)
      end do
      allocate(all(m, sum(counts) / max(m, 1)))
    else
      allocate(all(m, 0))
    end if
    if (everyone) then
      call MPI_Allgatherv(rows, m * n, MPI_DOUBLE_PRECISION, all, counts, displs, &
                          MPI_DOUBLE_PRECISION, self%handle)
    else
      call MPI_Gatherv(rows, m * n, MPI_DOUBLE_PRECISION, all, counts, displs, &
                       MPI_DOUBLE_PRECISION, 0, self%handle)
    end if
#endif
  end subroutine comm_gather_rows

  !> Every process sends each of its rows to the process `dest` names (itself included) and
  !> gets the rows sent to it, process by process in rank order, each process's in its order.
  subroutine comm_exchange_rows(self, rows, n, dest, got)
    class(empm_comm_t), intent(in) :: self                  !! communicator
    real(wp), intent(in), contiguous :: rows(:,:)           !! this process's rows (m, >= n)
    integer, intent(in) :: n                                !! its number of rows
    integer, intent(in) :: dest(:)                          !! the process of each (n), 0-based
    real(wp), allocatable, intent(out) :: got(:,:)          !! the rows received (m, k)
    real(wp), allocatable :: sorted(:,:)
    integer, allocatable :: scount(:), sdisp(:), rcount(:), rdisp(:), next(:)
    integer :: m, k, q
    logical :: grouped
    m = size(rows, 1)
    if (self%nranks <= 1) then
      allocate(got(m, n))
      got = rows(:, 1:n)
      return
    end if
    allocate(scount(self%nranks), sdisp(self%nranks), rcount(self%nranks), &
             rdisp(self%nranks), next(self%nranks))
    scount = 0
    do k = 1, n
      scount(dest(k) + 1) = scount(dest(k) + 1) + 1
    end do
    sdisp(1) = 0
    do q = 2, self%nranks
      sdisp(q) = sdisp(q - 1) + scount(q - 1)
    end do
    ! Rows grouped by destination, each group in this process's order: a copy, unless they
    ! come so already (particles in id order sent to the owners of blocks of ids).
    grouped = .true.
    do k = 2, n
      if (dest(k) < dest(k - 1)) then
        grouped = .false.; exit
      end if
    end do
    if (.not. grouped) then
      allocate(sorted(m, n))
      next = sdisp
      do k = 1, n
        q = dest(k) + 1
        next(q) = next(q) + 1
        sorted(:, next(q)) = rows(:, k)
      end do
    end if
    rcount = scount
#ifdef EMPM_USE_MPI
    call MPI_Alltoall(scount, 1, MPI_INTEGER, rcount, 1, MPI_INTEGER, self%handle)
#endif
    rdisp(1) = 0
    do q = 2, self%nranks
      rdisp(q) = rdisp(q - 1) + rcount(q - 1)
    end do
    allocate(got(m, sum(rcount)))
#ifdef EMPM_USE_MPI
    if (grouped) then
      call MPI_Alltoallv(rows, m * scount, m * sdisp, MPI_DOUBLE_PRECISION, got, m * rcount, &
                         m * rdisp, MPI_DOUBLE_PRECISION, self%handle)
    else
      call MPI_Alltoallv(sorted, m * scount, m * sdisp, MPI_DOUBLE_PRECISION, got, &
                         m * rcount, m * rdisp, MPI_DOUBLE_PRECISION, self%handle)
    end if
#endif
  end subroutine comm_exchange_rows

  !> Every process gets every process's integers: all(:, r + 1) = process r's `mine`.
  subroutine comm_allgather_ints(self, mine, all)
    class(empm_comm_t), intent(in) :: self          !! communicator
    integer, intent(in), contiguous :: mine(:)      !! this process's values
    integer, intent(out), contiguous :: all(:,:)    !! (size(mine), nranks)
    if (self%nranks <= 1) then
      all(:, 1) = mine
      return
    end if
#ifdef EMPM_USE_MPI
    call MPI_Allgather(mine, size(mine), MPI_INTEGER, all, size(mine), MPI_INTEGER, &
                       self%handle)
#endif
  end subroutine comm_allgather_ints

  !> Point-to-point swap with neighbours: segment k of `sbuf`, entries
  !> m (ptr(k) − 1) + 1 .. m (ptr(k+1) − 1), goes to process nbr(k), which sends back as many
  !> values into the same segment of `rbuf` (symmetric overlaps: both sides agree on ptr).
  subroutine comm_swap(self, nbr, ptr, m, sbuf, rbuf)
    class(empm_comm_t), intent(in) :: self                         !! communicator
    integer, intent(in) :: nbr(:)                                  !! neighbour processes
    integer, intent(in) :: ptr(:)                                  !! segment starts (size(nbr)+1)
    integer, intent(in) :: m                                       !! values per entry
    real(wp), intent(in), contiguous, asynchronous :: sbuf(:)      !! values to send
    real(wp), intent(inout), contiguous, asynchronous :: rbuf(:)   !! values received
#ifdef EMPM_USE_MPI
    type(MPI_Request) :: req(2 * size(nbr))
    integer :: k, i0, i1
    integer, parameter :: TAG = 7301
    if (self%nranks <= 1 .or. size(nbr) == 0) return
    do k = 1, size(nbr)
      i0 = m * (ptr(k) - 1) + 1; i1 = m * (ptr(k + 1) - 1)
      call MPI_Irecv(rbuf(i0:i1), i1 - i0 + 1, MPI_DOUBLE_PRECISION, nbr(k), TAG, &
                     self%handle, req(k))
    end do
    do k = 1, size(nbr)
      i0 = m * (ptr(k) - 1) + 1; i1 = m * (ptr(k + 1) - 1)
      call MPI_Isend(sbuf(i0:i1), i1 - i0 + 1, MPI_DOUBLE_PRECISION, nbr(k), TAG, &
                     self%handle, req(size(nbr) + k))
    end do
    call MPI_Waitall(2 * size(nbr), req, MPI_STATUSES_IGNORE)
#else
    associate (unused => [nbr, ptr, m], unused_s => sbuf, unused_r => rbuf); end associate
#endif
  end subroutine comm_swap

  !> End every process of the job with exit status `code` (MPI_Abort): for a failure the
  !> processes cannot recover from together. One process: stop with `code`.
  subroutine comm_abort(self, code)
    class(empm_comm_t), intent(in) :: self !! communicator
    integer, intent(in) :: code            !! exit status
#ifdef EMPM_USE_MPI
    if (self%nranks > 1) call MPI_Abort(self%handle, code)
#endif
    ! A constant stop code (Fortran 2008): the statuses empm uses.
    select case (code)
    case (2)
      error stop 2
    case (3)
      error stop 3
    case (4)
      error stop 4
    case default
      error stop 1
    end select
  end subroutine comm_abort

  !> Wait for every process.
  subroutine comm_barrier(self)
    class(empm_comm_t), intent(in) :: self !! communicator
    if (self%nranks <= 1) return
#ifdef EMPM_USE_MPI
    call MPI_Barrier(self%handle)
#endif
  end subroutine comm_barrier

  !> Release the communicator, and end MPI when this value started it (call before exiting).
  subroutine comm_finish(self)
    class(empm_comm_t), intent(inout) :: self !! communicator (serial afterwards)
#ifdef EMPM_USE_MPI
    logical :: down
    if (self%handle /= MPI_COMM_NULL) call MPI_Comm_free(self%handle)
    if (self%owns_mpi) then
      call MPI_Finalized(down)
      if (.not. down) call MPI_Finalize()
    end if
#endif
    self%owns_mpi = .false.
    self%rank = 0; self%nranks = 1
  end subroutine comm_finish
end module empm_comm
