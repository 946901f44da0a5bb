!> Material points from a Gmsh mesh (`.msh` format 4.1, ASCII): one particle at each quadrature
!> point of each element of the body's dimension, its volume the quadrature weight times
!> |det J| (2D: area per unit thickness, 1D: length per unit area).
!>
!> Elements used: 1 (2-node line, 1D), 2 (3-node triangle) and 3 (4-node quadrangle) in 2D,
!> 4 (4-node tetrahedron) and 5 (8-node hexahedron) in 3D. Elements of a lower dimension
!> (points, lines and surfaces bounding the body) are skipped; an element of the body's
!> dimension of another type, or of a higher dimension, is an input error. The quadrature order
!> `order` (the case's `ppc`, 1..4) gives order^ndim Gauss–Legendre points on lines,
!> quadrangles and hexahedra; on simplices 1 point (centroid) for order 1, the symmetric
!> 3-point (triangle) or 4-point (tetrahedron) rule for order 2, and the collapsed (Duffy)
!> order^ndim Gauss rule for orders 3 and 4. All weights are positive, and the volumes of an
!> element's particles sum to the element's area/volume exactly (for straight-sided elements).
!>
!> Malformed files are input errors (EMPM_ERR_INPUT) naming the file and the line.
module empm_gmsh
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: iso_c_binding, only: c_char, c_double, c_ptr, c_null_char, c_loc, &
    c_intptr_t
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, EMPM_ERR_INPUT, EMPM_OK
  use empm_files, only: empm_read_text
  use empm_strings, only: str
  implicit none
  private
  public :: empm_gmsh_points, empm_gmsh_type_name, empm_text_to_real

  integer, parameter :: MAXTOK = 40  !! tokens read per line (enough for 27-node elements)
  !> Largest coordinate magnitude [m] (the case reader's bound): det J and volumes then stay
  !> far from overflow.
  real(wp), parameter :: XMAX = 1.0e15_wp

  !> The file as lines (offsets into the text), with a cursor.
  type :: lines_t
    character(len=:), allocatable :: text
    integer, allocatable :: b(:), e(:)   !! first and last character of each line
    integer :: n = 0                     !! lines
    integer :: cur = 0                   !! last line consumed
  end type lines_t

  interface
    ! The C library's conversion of a decimal text (endptr: the first character not used).
    function c_strtod(text, endptr) bind(C, name='strtod') result(v)
      import :: c_char, c_double, c_ptr
      character(kind=c_char), intent(in) :: text(*)
      type(c_ptr), intent(out) :: endptr
      real(c_double) :: v
    end function c_strtod
  end interface

contains

  !> Read the Gmsh 4.1 ASCII mesh `path` and return its quadrature points in `ndim` dimensions.
  !> With `keep`, only every stride-th point is stored (a process's share when the body is
  !> dealt out among processes); every element is still read and checked.
  subroutine empm_gmsh_points(path, ndim, order, x, vol, err, keep, total)
    character(len=*), intent(in) :: path            !! .msh file
    integer, intent(in) :: ndim                     !! body dimension (1..3)
    integer, intent(in) :: order                    !! quadrature order per direction (1..4)
    real(wp), allocatable, intent(out) :: x(:,:)    !! particle positions (ndim, n) [m]
    real(wp), allocatable, intent(out) :: vol(:)    !! particle volumes (n) [m^ndim]
    type(empm_error_t), intent(inout) :: err        !! set on a malformed file
    integer, intent(in), optional :: keep(2)        !! (first, stride): store points first + 1,
                                                    !! first + 1 + stride, ... only (first
                                                    !! 0-based); default all
    integer, intent(out), optional :: total         !! points of the mesh (stored or not)
    type(lines_t) :: f
    type(empm_error_t) :: e
    integer(int64), allocatable :: tags(:)
    integer, allocatable :: perm(:), nline(:)
    real(wp), allocatable :: xyz(:,:)
    logical :: have_format, have_nodes, have_elems
    character(len=:), allocatable :: ln
    integer :: np, nall, kp(2)
    kp = [0, 1]
    if (present(keep)) kp = keep
    if (present(total)) total = 0
    call empm_read_text(path, f%text, e)
    if (e%code /= EMPM_OK) then
      call err%set(EMPM_ERR_INPUT, 'cannot read the mesh: '//e%message, file=path); return
    end if
    call split_lines(f)
    have_format = .false.; have_nodes = .false.; have_elems = .false.
    np = 0; nall = 0
    allocate(x(ndim, 64), vol(64))
    do while (f%cur < f%n)
      f%cur = f%cur + 1
      ln = trim(adjustl(line(f, f%cur)))
      if (len(ln) == 0) cycle
      if (ln(1:1) /= '$') then
        call fail('expected a section header such as $Nodes, got '''//clip(ln)//''''); return
      end if
      if (.not. have_format .and. ln /= '$MeshFormat') then
        call fail('expected $MeshFormat first (a Gmsh .msh file)'); return
      end if
      select case (ln)
      case ('$MeshFormat')
        call read_format(); have_format = .true.
      case ('$Nodes')
        call read_nodes(); have_nodes = .true.
      case ('$Elements')
        if (.not. have_nodes) then
          call fail('$Elements before $Nodes'); return
        end if
        call read_elements(); have_elems = .true.
      case default
        call skip_section(ln(2:))
      end select
      if (err%code /= EMPM_OK) return
    end do
    if (.not. have_format) then
      call err%set(EMPM_ERR_INPUT, 'empty file: expected a Gmsh 4.1 mesh', file=path); return
    end if
    if (.not. (have_nodes .and. have_elems)) then
      call err%set(EMPM_ERR_INPUT, 'missing section '//merge('$Nodes   ', '$Elements', &
        .not. have_nodes), file=path); return
    end if
    if (nall == 0) then
      call err%set(EMPM_ERR_INPUT, 'the mesh has no '//str(ndim)//'-D element (types '// &
        supported(ndim)//')', file=path); return
    end if
    x = x(:, 1:np); vol = vol(1:np)
    if (present(total)) total = nall

  contains

    subroutine fail(text, at)
      character(len=*), intent(in) :: text
      integer, intent(in), optional :: at
      if (present(at)) then
        call err%set(EMPM_ERR_INPUT, text, file=path, line=at)
      else
        call err%set(EMPM_ERR_INPUT, text, file=path, line=f%cur)
      end if
    end subroutine fail

    !> Next line of a section, or an error when the file or the section ends first.
    logical function next(section, what) result(ok)
      character(len=*), intent(in) :: section, what
      ok = .false.
      if (f%cur >= f%n) then
        call fail('truncated $'//section//' section: the file ends before '//what, f%n + 1)
        return
      end if
      f%cur = f%cur + 1
      ln = trim(adjustl(line(f, f%cur)))
      if (len(ln) > 0 .and. what(1:1) /= '$') then  ! (what = '$End...': the caller checks)
        if (ln(1:1) == '$') then
          call fail('truncated $'//section//' section: '''//clip(ln)//''' before '//what)
          return
        end if
      end if
      ok = .true.
    end function next

    !> Exactly `n` integers on the current line.
    logical function ints(v, n, what) result(ok)
      integer(int64), intent(out) :: v(:)
      integer, intent(in) :: n
      character(len=*), intent(in) :: what
      character(len=64) :: tok(MAXTOK)
      integer :: nt, i, ios
      ok = .false.; v = 0
      call tokens(ln, tok, nt)
      if (nt /= n) then
        call fail('expected '//what//' ('//str(n)//' integers), got '''//clip(ln)//''''); return
      end if
      do i = 1, min(nt, size(v))
        ios = 1
        if (verify(trim(tok(i)), '+-0123456789') == 0) read(tok(i), *, iostat=ios) v(i)
        if (ios /= 0) then
          call fail('expected an integer in '//what//', got '''//trim(tok(i))//''''); return
        end if
      end do
      ok = .true.
    end function ints

    subroutine read_format()
      character(len=64) :: tok(MAXTOK)
      integer :: nt
      if (.not. next('MeshFormat', 'the version line')) return
      call tokens(ln, tok, nt)
      if (nt < 3) then
        call fail('expected "version file-type data-size" (e.g. 4.1 0 8), got '''// &
          clip(ln)//''''); return
      end if
      if (trim(tok(1)) /= '4.1') then
        call fail('unsupported MSH version '//trim(tok(1))//': expected 4.1 (Gmsh: '// &
          '-format msh41, or Mesh.MshFileVersion = 4.1)'); return
      end if
      if (trim(tok(2)) /= '0') then
        call fail('binary .msh files are not supported: save as ASCII (Gmsh: -bin 0, or '// &
          'Mesh.Binary = 0)'); return
      end if
      if (.not. next('MeshFormat', '$EndMeshFormat')) return
      if (ln /= '$EndMeshFormat') call fail('expected $EndMeshFormat, got '''//clip(ln)//'''')
    end subroutine read_format

    subroutine skip_section(name)
      character(len=*), intent(in) :: name
      integer :: start
      start = f%cur
      do while (f%cur < f%n)
        f%cur = f%cur + 1
        if (trim(adjustl(line(f, f%cur))) == '$End'//name) return
      end do
      call fail('truncated $'//name//' section: no $End'//name, start)
    end subroutine skip_section

    subroutine read_nodes()
      integer(int64) :: h(4), b(4), t(1)
      integer :: nblock, nnode, k, i, j, i0, nt, ios
      logical :: big
      character(len=64) :: tok(MAXTOK)
      if (.not. next('Nodes', 'its header')) return
      if (.not. ints(h, 4, 'numEntityBlocks numNodes minNodeTag maxNodeTag')) return
      if (any(h(1:2) < 0) .or. h(2) > huge(1)) then
        call fail('bad $Nodes header '''//clip(ln)//''''); return
      end if
      nblock = int(h(1)); nnode = int(h(2))
      allocate(tags(nnode), xyz(3, nnode), nline(nnode))
      i0 = 0
      do k = 1, nblock
        if (.not. next('Nodes', 'node block '//str(k)//' of '//str(nblock))) return
        if (.not. ints(b, 4, 'entityDim entityTag parametric numNodesInBlock')) return
        if (b(4) < 0 .or. i0 + b(4) > nnode) then
          call fail('node block '//str(k)//' has more nodes than the header''s '// &
            str(nnode)); return
        end if
        do i = i0 + 1, i0 + int(b(4))
          if (.not. next('Nodes', str(nnode)//' nodes were read')) return
          if (.not. ints(t, 1, 'a node tag')) return
          tags(i) = t(1)
        end do
        do i = i0 + 1, i0 + int(b(4))
          if (.not. next('Nodes', str(nnode)//' nodes were read')) return
          call tokens(ln, tok, nt)
          if (nt < 3) then
            call fail('expected node coordinates "x y z", got '''//clip(ln)//''''); return
          end if
          do j = 1, 3
            ios = merge(0, 1, empm_text_to_real(tok(j), xyz(j, i), big))
            if (big .or. (ios == 0 .and. abs(xyz(j, i)) > XMAX)) then
              call fail('coordinate '//'xyz'(j:j)//' = '//trim(tok(j))//' beyond +-1e15 m'); return
            end if
            if (ios /= 0) then
              call fail('expected a number for coordinate '//'xyz'(j:j)//', got '''// &
                trim(tok(j))//''''); return
            end if
          end do
          nline(i) = f%cur
        end do
        i0 = i0 + int(b(4))
      end do
      if (i0 /= nnode) then
        call fail('the $Nodes header announces '//str(nnode)//' nodes, the blocks hold '// &
          str(i0)); return
      end if
      if (.not. next('Nodes', '$EndNodes')) return
      if (ln /= '$EndNodes') then
        call fail('expected $EndNodes after '//str(nnode)//' nodes, got '''//clip(ln)//''''); return
      end if
      allocate(perm(nnode))
      do i = 1, nnode
        perm(i) = i
      end do
      call sort_by_tag(tags, perm)
      do i = 2, nnode
        if (tags(perm(i)) == tags(perm(i - 1))) then
          call fail('node tag '//str(int(tags(perm(i))))//' given twice', nline(perm(i))); return
        end if
      end do
    end subroutine read_nodes

    subroutine read_elements()
      integer(int64) :: h(4), b(4), v(MAXTOK)
      integer :: nblock, k, i, edim, etype, nn, a, idx(8), nel, nseen
      real(wp) :: xe(3, 8)
      if (.not. next('Elements', 'its header')) return
      if (.not. ints(h, 4, 'numEntityBlocks numElements minElementTag maxElementTag')) return
      if (any(h(1:2) < 0) .or. h(2) > huge(1)) then
        call fail('bad $Elements header '''//clip(ln)//''''); return
      end if
      nblock = int(h(1)); nel = int(h(2)); nseen = 0
      do k = 1, nblock
        if (.not. next('Elements', 'element block '//str(k)//' of '//str(nblock))) return
        if (.not. ints(b, 4, 'entityDim entityTag elementType numElementsInBlock')) return
        edim = int(b(1)); etype = int(b(3))
        if (b(4) < 0 .or. nseen + b(4) > nel) then
          call fail('element block '//str(k)//' has more elements than the header''s '// &
            str(nel)); return
        end if
        if (edim > ndim) then
          call fail(str(edim)//'-D elements (type '//str(etype)//', '// &
            empm_gmsh_type_name(etype)//') in a '//str(ndim)//'-D case (&grid ndim)'); return
        end if
        nn = 0
        if (edim == ndim) then
          nn = nodes_of(etype, ndim)
          if (nn == 0) then
            call fail('unsupported element type '//str(etype)//' ('// &
              empm_gmsh_type_name(etype)//'); supported in '//str(ndim)//'-D: '// &
              supported(ndim)); return
          end if
        end if
        do i = 1, int(b(4))
          if (.not. next('Elements', str(nel)//' elements were read')) return
          if (nn == 0) cycle  ! a lower-dimensional element: not part of the body
          if (.not. ints(v, 1 + nn, 'an element tag and '//str(nn)//' node tags')) return
          do a = 1, nn
            idx(a) = find_tag(tags, perm, v(1 + a))
            if (idx(a) == 0) then
              call fail('element '//str(int(v(1)))//': node '//str(int(v(1 + a)))// &
                ' is not in $Nodes'); return
            end if
            if (any(abs(xyz(ndim + 1:3, idx(a))) > 1.0e-12_wp * &
                    max(1.0_wp, maxval(abs(xyz(:, idx(a))))))) then
              call fail('node '//str(int(v(1 + a)))//' of a '//str(ndim)//'-D element has '// &
                'a non-zero '//merge('z   ', 'y, z', ndim == 2)//' coordinate: a '// &
                str(ndim)//'-D mesh must lie in the '// &
                merge('plane z = 0', 'x axis     ', ndim == 2), nline(idx(a))); return
            end if
            xe(:, a) = xyz(:, idx(a))
          end do
          call add_element(etype, xe(1:ndim, 1:nn), int(v(1)))
          if (err%code /= EMPM_OK) return
        end do
        nseen = nseen + int(b(4))
      end do
      if (nseen /= nel) then
        call fail('the $Elements header announces '//str(nel)//' elements, the blocks hold '// &
          str(nseen)); return
      end if
      if (.not. next('Elements', '$EndElements')) return
      if (ln /= '$EndElements') &
        call fail('expected $EndElements after '//str(nel)//' elements, got '''//clip(ln)//'''')
    end subroutine read_elements

    subroutine add_element(etype, xe, tag)
      integer, intent(in) :: etype
      real(wp), intent(in) :: xe(:,:)
      integer, intent(in) :: tag
      real(wp) :: xq(3, 64), wq(64)
      real(wp), allocatable :: tx(:,:), tv(:)
      integer :: nq, info, q, k
      call element_points(etype, xe, order, xq, wq, nq, info)
      if (info /= 0) then
        call fail('element '//str(tag)//' ('//empm_gmsh_type_name(etype)//') is '//trim( &
          merge('degenerate (zero size)                     ', &
          'inverted or non-convex (det J changes sign)', info == 1))); return
      end if
      if (np + nq > size(vol)) then
        allocate(tx(ndim, 2 * (np + nq)), tv(2 * (np + nq)))
        tx(:, 1:np) = x(:, 1:np); tv(1:np) = vol(1:np)
        call move_alloc(tx, x); call move_alloc(tv, vol)
      end if
      do q = 1, nq
        k = nall + q - 1 ! the point's 0-based number in the mesh
        if (k < kp(1) .or. mod(k - kp(1), kp(2)) /= 0) cycle
        np = np + 1
        x(:, np) = xq(1:ndim, q); vol(np) = wq(q)
      end do
      nall = nall + nq
    end subroutine add_element
  end subroutine empm_gmsh_points

  !> Quadrature points of one element (nodes `xe(ndim, nnode)` in Gmsh order) and their
  !> volumes (weight x |det J|). info: 0 ok, 1 degenerate, 2 det J changes sign.
  pure subroutine element_points(etype, xe, order, xq, vq, nq, info)
    integer, intent(in) :: etype            !! Gmsh element type (1..5)
    real(wp), intent(in) :: xe(:,:)         !! node coordinates (ndim, nnode)
    integer, intent(in) :: order            !! points per direction (1..4)
    real(wp), intent(out) :: xq(3, 64)      !! point positions (first ndim rows)
    real(wp), intent(out) :: vq(64)         !! point volumes
    integer, intent(out) :: nq              !! points
    integer, intent(out) :: info            !! status
    real(wp) :: g(4), w(4), xi(3, 64), wr(64), nsh(8), dn(3, 8), jac(3, 3), det(64), scale
    integer :: nd, nn, i, j, k, q
    nd = size(xe, 1); nn = size(xe, 2)
    xq = 0.0_wp; vq = 0.0_wp; info = 0
    call gauss01(order, g, w)
    nq = 0
    select case (etype)
    case (1, 3, 5)  ! tensor-product Gauss on [0,1]^nd, weights summing to 1
      do k = 1, merge(order, 1, nd == 3)
        do j = 1, merge(order, 1, nd >= 2)
          do i = 1, order
            nq = nq + 1
            xi(:, nq) = [g(i), g(j), g(k)]
            wr(nq) = w(i) * merge(w(j), 1.0_wp, nd >= 2) * merge(w(k), 1.0_wp, nd == 3)
          end do
        end do
      end do
    case (2)
      call simplex_rule(2, order, g, w, xi, wr, nq)
    case (4)
      call simplex_rule(3, order, g, w, xi, wr, nq)
    end select
    do q = 1, nq
      call shape_fn(etype, xi(:, q), nsh, dn)
      xq(1:nd, q) = matmul(xe, nsh(1:nn))
      jac(1:nd, 1:nd) = matmul(xe, transpose(dn(1:nd, 1:nn)))
      select case (nd)
      case (1)
        det(q) = jac(1, 1)
      case (2)
        det(q) = jac(1, 1) * jac(2, 2) - jac(1, 2) * jac(2, 1)
      case default
        det(q) = jac(1, 1) * (jac(2, 2) * jac(3, 3) - jac(2, 3) * jac(3, 2)) &
               - jac(1, 2) * (jac(2, 1) * jac(3, 3) - jac(2, 3) * jac(3, 1)) &
               + jac(1, 3) * (jac(2, 1) * jac(3, 2) - jac(2, 2) * jac(3, 1))
      end select
      ! Reference measure: 1 for [0,1]^nd, 1/2 triangle, 1/6 tetrahedron.
      vq(q) = wr(q) * abs(det(q)) * merge(0.5_wp, merge(1.0_wp / 6.0_wp, 1.0_wp, etype == 4), &
                                          etype == 2)
    end do
    scale = maxval(maxval(xe, dim=2) - minval(xe, dim=2))**nd
    if (any(abs(det(1:nq)) <= 1.0e-12_wp * scale)) then
      info = 1
    else if (any(det(1:nq) > 0.0_wp) .and. any(det(1:nq) < 0.0_wp)) then
      info = 2
    end if
  end subroutine element_points

  !> Points (reference coordinates) and weights (summing to 1) on the unit triangle (d = 2) or
  !> tetrahedron (d = 3).
  pure subroutine simplex_rule(d, order, g, w, xi, wr, nq)
    integer, intent(in) :: d, order
    real(wp), intent(in) :: g(4), w(4)
    real(wp), intent(out) :: xi(3, 64), wr(64)
    integer, intent(out) :: nq
    real(wp), parameter :: TA = 2.0_wp / 3.0_wp, TB = 1.0_wp / 6.0_wp
    real(wp), parameter :: SA = 0.5854101966249685_wp, SB = 0.1381966011250105_wp
    integer :: i, j, k
    xi = 0.0_wp; wr = 0.0_wp; nq = 0
    if (order == 1) then
      nq = 1; xi(1:d, 1) = 1.0_wp / (d + 1); wr(1) = 1.0_wp
    else if (order == 2 .and. d == 2) then
      nq = 3
      xi(1:2, 1) = [TB, TB]; xi(1:2, 2) = [TA, TB]; xi(1:2, 3) = [TB, TA]
      wr(1:3) = 1.0_wp / 3.0_wp
    else if (order == 2) then
      nq = 4
      xi(:, 1) = [SB, SB, SB]; xi(:, 2) = [SA, SB, SB]; xi(:, 3) = [SB, SA, SB]
      xi(:, 4) = [SB, SB, SA]
      wr(1:4) = 0.25_wp
    else if (d == 2) then
      ! Collapsed (Duffy) square: xi = u, eta = v (1 - u), Jacobian 1 - u.
      do j = 1, order
        do i = 1, order
          nq = nq + 1
          xi(1:2, nq) = [g(i), g(j) * (1.0_wp - g(i))]
          wr(nq) = 2.0_wp * w(i) * w(j) * (1.0_wp - g(i))
        end do
      end do
    else
      ! Collapsed cube: Jacobian (1 - u)^2 (1 - v).
      do k = 1, order
        do j = 1, order
          do i = 1, order
            nq = nq + 1
            xi(:, nq) = [g(i), g(j) * (1.0_wp - g(i)), g(k) * (1.0_wp - g(i)) * (1.0_wp - g(j))]
            wr(nq) = 6.0_wp * w(i) * w(j) * w(k) * (1.0_wp - g(i))**2 * (1.0_wp - g(j))
          end do
        end do
      end do
    end if
  end subroutine simplex_rule

  !> Shape functions and their reference derivatives; reference cells [0,1]^d for lines,
  !> quadrangles and hexahedra, the unit simplex for triangles and tetrahedra (Gmsh node order).
  pure subroutine shape_fn(etype, xi, n, dn)
    integer, intent(in) :: etype
    real(wp), intent(in) :: xi(3)
    real(wp), intent(out) :: n(8), dn(3, 8)
    ! Corner of each node of the [0,1]^3 hexahedron (and of the quadrangle, first four).
    integer, parameter :: C(3, 8) = reshape([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, &
                                             0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1], [3, 8])
    real(wp) :: f(3, 0:1), df(3, 0:1)
    integer :: a, nd, nn
    n = 0.0_wp; dn = 0.0_wp
    select case (etype)
    case (2)
      n(1:3) = [1.0_wp - xi(1) - xi(2), xi(1), xi(2)]
      dn(1:2, 1) = -1.0_wp; dn(1, 2) = 1.0_wp; dn(2, 3) = 1.0_wp
    case (4)
      n(1:4) = [1.0_wp - xi(1) - xi(2) - xi(3), xi(1), xi(2), xi(3)]
      dn(1:3, 1) = -1.0_wp; dn(1, 2) = 1.0_wp; dn(2, 3) = 1.0_wp; dn(3, 4) = 1.0_wp
    case default  ! 1, 3, 5: products of 1D linear functions
      nd = merge(1, merge(2, 3, etype == 3), etype == 1)
      nn = 2**nd
      f(:, 0) = 1.0_wp - xi; f(:, 1) = xi
      df(:, 0) = -1.0_wp; df(:, 1) = 1.0_wp
      do a = 1, nn
        n(a) = lin(1, a) * merge(lin(2, a), 1.0_wp, nd >= 2) * merge(lin(3, a), 1.0_wp, nd == 3)
        dn(1, a) = dlin(1, a) * merge(lin(2, a), 1.0_wp, nd >= 2) * &
                   merge(lin(3, a), 1.0_wp, nd == 3)
        if (nd >= 2) dn(2, a) = lin(1, a) * dlin(2, a) * merge(lin(3, a), 1.0_wp, nd == 3)
        if (nd == 3) dn(3, a) = lin(1, a) * lin(2, a) * dlin(3, a)
      end do
    end select
  contains
    pure real(wp) function lin(d, a)
      integer, intent(in) :: d, a
      lin = f(d, C(d, a))
    end function lin
    pure real(wp) function dlin(d, a)
      integer, intent(in) :: d, a
      dlin = df(d, C(d, a))
    end function dlin
  end subroutine shape_fn

  !> Gauss–Legendre points on [0, 1] and weights summing to 1.
  pure subroutine gauss01(n, g, w)
    integer, intent(in) :: n
    real(wp), intent(out) :: g(4), w(4)
    g = 0.5_wp; w = 0.0_wp
    select case (n)
    case (1)
      w(1) = 1.0_wp
    case (2)
      g(1:2) = 0.5_wp * (1.0_wp + [-1.0_wp, 1.0_wp] / sqrt(3.0_wp)); w(1:2) = 0.5_wp
    case (3)
      g(1:3) = 0.5_wp * (1.0_wp + [-sqrt(0.6_wp), 0.0_wp, sqrt(0.6_wp)])
      w(1:3) = [5.0_wp, 8.0_wp, 5.0_wp] / 18.0_wp
    case default
      g = 0.5_wp * (1.0_wp + [-0.861136311594052575_wp, -0.339981043584856265_wp, &
                               0.339981043584856265_wp, 0.861136311594052575_wp])
      w = 0.5_wp * [0.347854845137453857_wp, 0.652145154862546143_wp, &
                    0.652145154862546143_wp, 0.347854845137453857_wp]
    end select
  end subroutine gauss01

  !> Nodes of a supported element type of dimension `ndim`, 0 when not supported.
  pure integer function nodes_of(etype, ndim) result(nn)
    integer, intent(in) :: etype, ndim
    nn = 0
    select case (etype)
    case (1)
      if (ndim == 1) nn = 2
    case (2)
      if (ndim == 2) nn = 3
    case (3)
      if (ndim == 2) nn = 4
    case (4)
      if (ndim == 3) nn = 4
    case (5)
      if (ndim == 3) nn = 8
    end select
  end function nodes_of

  pure function supported(ndim) result(s)
    integer, intent(in) :: ndim
    character(len=:), allocatable :: s
    select case (ndim)
    case (1)
      s = '1 (2-node line)'
    case (2)
      s = '2 (3-node triangle), 3 (4-node quadrangle)'
    case default
      s = '4 (4-node tetrahedron), 5 (8-node hexahedron)'
    end select
  end function supported

  !> A readable name of a Gmsh element type, for messages.
  pure function empm_gmsh_type_name(etype) result(s)
    integer, intent(in) :: etype        !! Gmsh element type number
    character(len=:), allocatable :: s  !! e.g. '6-node triangle'
    select case (etype)
    case (1); s = '2-node line'
    case (2); s = '3-node triangle'
    case (3); s = '4-node quadrangle'
    case (4); s = '4-node tetrahedron'
    case (5); s = '8-node hexahedron'
    case (6); s = '6-node prism'
    case (7); s = '5-node pyramid'
    case (8); s = '3-node line'
    case (9); s = '6-node triangle'
    case (10); s = '9-node quadrangle'
    case (11); s = '10-node tetrahedron'
    case (12); s = '27-node hexahedron'
    case (15); s = '1-node point'
    case (16); s = '8-node quadrangle'
    case (17); s = '20-node hexahedron'
    case default; s = 'Gmsh element type '//str(etype)
    end select
  end function empm_gmsh_type_name

  ! ---- text helpers --------------------------------------------------------------------------

  !> The value of one decimal number, `[sign] digits [. digits] [e|E|d|D [sign] digits]` with
  !> blanks around it, or with a signed exponent without its letter as Fortran writes an
  !> exponent beyond 99 (`1.5-120`); not 'inf', 'nan', nor hexadecimal.
  !> Converted by the C library's `strtod`, correctly rounded: the value of Fortran's
  !> list-directed read, which calls it too (tests/unit/test_number_text.pf), at a fraction of
  !> its cost; by that read when `strtod` stops short (a host program whose locale's decimal
  !> point is not '.'). A magnitude of 1e301 or more is refused before conversion (converting
  !> 1e400 would trap with -ffpe-trap=overflow).
  logical function empm_text_to_real(t, x, too_big) result(ok)
    character(len=*), intent(in) :: t   !! text of one number
    real(wp), intent(out) :: x          !! its value (0 when not ok)
    logical, intent(out), optional :: too_big !! a number, but of magnitude >= 1e301
    integer, parameter :: NBUF = 128
    character(kind=c_char), target :: buf(NBUF)
    type(c_ptr) :: endp
    integer :: b, e, i, k, ex, lead, ndig, ios, n, m
    logical :: point
    x = 0.0_wp; ok = .false.
    if (present(too_big)) too_big = .false.
    e = len_trim(t)
    if (e == 0) return
    b = verify(t(1:e), ' ')
    ! The mantissa: digits with at most one point; its digits before the point, leading zeros
    ! dropped, give the decimal magnitude with the exponent.
    i = b
    if (t(i:i) == '+' .or. t(i:i) == '-') i = i + 1
    ndig = 0; lead = 0; point = .false.
    do while (i <= e)
      if (t(i:i) >= '0' .and. t(i:i) <= '9') then
        ndig = ndig + 1
        if (.not. point .and. (lead > 0 .or. t(i:i) /= '0')) lead = lead + 1
      else if (t(i:i) == '.' .and. .not. point) then
        point = .true.
      else
        exit
      end if
      i = i + 1
    end do
    if (ndig == 0) return
    ex = 0
    m = 0   ! where the exponent's letter goes in the C text (one without a letter)
    if (i <= e) then
      ! The exponent: a letter and a sign, or a sign, then digits (at most 9 after leading
      ! zeros: beyond, a magnitude is too big, or below any double's, anyway).
      if (index('eEdD', t(i:i)) > 0) then
        i = i + 1
      else if (t(i:i) == '+' .or. t(i:i) == '-') then
        m = i - b + 1
      else
        return
      end if
      k = 1
      if (i <= e) then
        if (t(i:i) == '+' .or. t(i:i) == '-') then
          if (t(i:i) == '-') k = -1
          i = i + 1
        end if
      end if
      if (i > e) return
      if (verify(t(i:e), '0123456789') > 0) return
      do while (i < e .and. t(i:i) == '0')
        i = i + 1
      end do
      if (e - i + 1 > 9) return
      do n = i, e
        ex = 10 * ex + (iachar(t(n:n)) - iachar('0'))
      end do
      ex = k * ex
    end if
    if (lead + ex > 301) then
      if (present(too_big)) too_big = .true.
      return
    end if
    n = e - b + 1
    ios = 1
    if (n + 1 < NBUF) then
      k = 0
      do i = 1, n
        if (i == m) then
          k = k + 1; buf(k) = 'e'
        end if
        k = k + 1; buf(k) = t(b + i - 1:b + i - 1)
        if (buf(k) == 'd' .or. buf(k) == 'D') buf(k) = 'e'
      end do
      n = k
      buf(n + 1) = c_null_char
      x = c_strtod(buf, endp)
      if (transfer(endp, 0_c_intptr_t) - transfer(c_loc(buf), 0_c_intptr_t) == n) ios = 0
    end if
    if (ios /= 0) read(t(b:e), *, iostat=ios) x
    ok = ios == 0
    if (ok) ok = ieee_is_finite(x)
    if (.not. ok) x = 0.0_wp
  end function empm_text_to_real

  subroutine split_lines(f)
    type(lines_t), intent(inout) :: f
    integer :: i, n, k
    n = len(f%text)
    k = 1
    do i = 1, n
      if (f%text(i:i) == new_line('a')) k = k + 1
    end do
    allocate(f%b(k), f%e(k))
    f%n = 0
    k = 1
    do i = 1, n
      if (f%text(i:i) == new_line('a')) then
        f%n = f%n + 1; f%b(f%n) = k; f%e(f%n) = i - 1; k = i + 1
      end if
    end do
    if (k <= n) then  ! last line without a newline
      f%n = f%n + 1; f%b(f%n) = k; f%e(f%n) = n
    end if
  end subroutine split_lines

  !> Line i without a trailing carriage return, tabs as blanks.
  function line(f, i) result(s)
    type(lines_t), intent(in) :: f
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    integer :: k
    s = f%text(f%b(i):f%e(i))
    if (len(s) > 0) then
      if (s(len(s):len(s)) == achar(13)) s = s(1:len(s) - 1)
    end if
    do k = 1, len(s)
      if (s(k:k) == achar(9)) s(k:k) = ' '
    end do
  end function line

  pure subroutine tokens(s, tok, nt)
    character(len=*), intent(in) :: s
    character(len=64), intent(out) :: tok(:)
    integer, intent(out) :: nt
    integer :: i, b
    nt = 0; tok = ''
    i = 1
    do while (i <= len(s))
      if (s(i:i) == ' ') then
        i = i + 1; cycle
      end if
      b = i
      do while (i <= len(s))
        if (s(i:i) == ' ') exit
        i = i + 1
      end do
      nt = nt + 1
      if (nt <= size(tok)) tok(nt) = s(b:i - 1)
    end do
    nt = min(nt, size(tok) + 1)
  end subroutine tokens

  pure function clip(s) result(r)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: r
    r = s
    if (len(r) > 60) r = r(1:57)//'...'
  end function clip

  !> Heap sort of `perm` by `tags(perm)`.
  pure subroutine sort_by_tag(tags, perm)
    integer(int64), intent(in) :: tags(:)
    integer, intent(inout) :: perm(:)
    integer :: n, i, t
    n = size(perm)
    do i = n / 2, 1, -1
      call sift(perm, i, n)
    end do
    do i = n, 2, -1
      t = perm(1); perm(1) = perm(i); perm(i) = t
      call sift(perm, 1, i - 1)
    end do
  contains
    pure subroutine sift(perm, start, last)
      integer, intent(inout) :: perm(:)
      integer, intent(in) :: start, last
      integer :: r, c, t
      r = start
      do while (2 * r <= last)
        c = 2 * r
        if (c < last) then
          if (tags(perm(c + 1)) > tags(perm(c))) c = c + 1
        end if
        if (tags(perm(r)) >= tags(perm(c))) return
        t = perm(r); perm(r) = perm(c); perm(c) = t
        r = c
      end do
    end subroutine sift
  end subroutine sort_by_tag

  !> Index of node `tag` (binary search), 0 if absent.
  pure integer function find_tag(tags, perm, tag) result(k)
    integer(int64), intent(in) :: tags(:)
    integer, intent(in) :: perm(:)
    integer(int64), intent(in) :: tag
    integer :: lo, hi, mid
    lo = 1; hi = size(perm); k = 0
    do while (lo <= hi)
      mid = (lo + hi) / 2
      if (tags(perm(mid)) == tag) then
        k = perm(mid); return
      else if (tags(perm(mid)) < tag) then
        lo = mid + 1
      else
        hi = mid - 1
      end if
    end do
  end function find_tag
end module empm_gmsh
