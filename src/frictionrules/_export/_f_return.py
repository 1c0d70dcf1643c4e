"""The return mapping in fixed-form Fortran 77: the text the Abaqus targets write after the
law's local subroutines.

Line for line the algorithm of the compiled return mapping (``contact/_return_kernel.py``) and
of the C target (``_c_template.py``): limit check, Newton on the dimensionless residual with a
backtracking line search, apex of a cone, consistent tangent. ``@P@`` is replaced by the prefix
of the law's names and ``@PARAMS@`` by the PARAMETER statements of the layout (``NQ``, ``NQS``,
``M``, ``NSIZE``, ``ICLIP``, ``HASKAP``, ``KAPPA``, the offsets ``OFF*``, the status codes
``KELAS``, ``KPLAS``, ``KOPEN``, ``KAPEX``, ``KFAIL`` and the substep depth ``MAXDEP``), the
other ``@...@`` by the numbers of :mod:`frictionrules._returnspec` (one home for the NumPy,
Numba, C and Fortran returns). Every name is declared (``IMPLICIT NONE``); no line passes
column 72.
"""

CORE = """\
C ----------------------------------------------------------------------
C The law's quantities at (T1, T2, N, Q) into W, made finite at kinks
C (the kink rule).
      SUBROUTINE @P@EV(S0, S1, S2, Q, P, W, LEVEL)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION S0, S1, S2, Q(NQS), P(*), W(*)
      INTEGER LEVEL, K, LAST, J
      DOUBLE PRECISION SN, R, BEST, A
      SN = S2
      IF (ICLIP .EQ. 1) SN = MAX(S2, 0.0D0)
      LAST = NSIZE
      IF (LEVEL .EQ. 0) THEN
         CALL @P@LF(S0, S1, SN, Q, P, W)
         LAST = 1
      ELSE IF (LEVEL .EQ. 1) THEN
         CALL @P@L1(S0, S1, SN, Q, P, W)
      ELSE
         CALL @P@L2(S0, S1, SN, Q, P, W)
      END IF
      DO 10 K = 2, LAST
         IF (.NOT. (ABS(W(K)) .LE. HUGE(1.0D0))) W(K) = 0.0D0
   10 CONTINUE
      IF (.NOT. (ABS(W(1)) .LE. HUGE(1.0D0))) THEN
         R = @KINK_RADIUS@*(SQRT(S0*S0 + S1*S1) + ABS(SN)) + 1.0D-300
         BEST = -HUGE(1.0D0)
         DO 20 J = 0, @KINK_LAST@
            A = @KINK_ANGLE@*J
            CALL @P@LF(S0 + R*COS(A), S1 + R*SIN(A), SN, Q, P, W)
            IF (W(1) .GT. BEST) BEST = W(1)
   20    CONTINUE
         W(1) = BEST
      END IF
      RETURN
      END
C ----------------------------------------------------------------------
C Scaled backward-Euler residual at X = (SIGMA, Q, DLAM) into R; its
C norm (1D300 where a component passes 1D150: the line search rejects).
      DOUBLE PRECISION FUNCTION @P@RS(W, X, STR, QN, DV, ROWS, R)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION W(*), X(M), STR(3), QN(NQS), DV(3)
      DOUBLE PRECISION ROWS(M), R(M), ACC
      INTEGER A, J, NQV
      NQV = NQ
      @P@RS = 1.0D300
      ACC = 0.0D0
      DO 10 A = 1, 3
         R(A) = (X(A) - STR(A) + X(M)*DV(A)*W(OFFDG + A))*ROWS(A)
         IF (.NOT. (ABS(R(A)) .LT. 1.0D150)) RETURN
         ACC = ACC + R(A)*R(A)
   10 CONTINUE
      DO 20 J = 1, NQV
         R(3 + J) = (X(3 + J) - QN(J) - X(M)*W(OFFH + J))*ROWS(3 + J)
         IF (.NOT. (ABS(R(3 + J)) .LT. 1.0D150)) RETURN
         ACC = ACC + R(3 + J)**2
   20 CONTINUE
      R(M) = W(1)*ROWS(M)
      IF (.NOT. (ABS(R(M)) .LT. 1.0D150)) RETURN
      ACC = ACC + R(M)*R(M)
      @P@RS = SQRT(ACC)
      RETURN
      END
C ----------------------------------------------------------------------
C Newton Jacobian of the residual in (SIGMA, Q, DLAM), unscaled.
      SUBROUTINE @P@JA(W, ALAM, DV, AJ)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION W(*), ALAM, DV(3), AJ(M, M)
      INTEGER A, B, J, K, NQV
      NQV = NQ
      DO 30 A = 1, 3
         DO 10 B = 1, 3
            AJ(A, B) = ALAM*DV(A)*W(OFFHGG + 3*(A - 1) + B)
   10    CONTINUE
         AJ(A, A) = AJ(A, A) + 1.0D0
         DO 20 J = 1, NQV
            AJ(A, 3 + J) = ALAM*DV(A)*W(OFFHGQ + NQ*(A - 1) + J)
   20    CONTINUE
         AJ(A, M) = DV(A)*W(OFFDG + A)
   30 CONTINUE
      DO 60 J = 1, NQV
         DO 40 B = 1, 3
            AJ(3 + J, B) = -ALAM*W(OFFDHS + 3*(J - 1) + B)
   40    CONTINUE
         DO 50 K = 1, NQV
            AJ(3 + J, 3 + K) = -ALAM*W(OFFDHQ + NQ*(J - 1) + K)
   50    CONTINUE
         AJ(3 + J, 3 + J) = AJ(3 + J, 3 + J) + 1.0D0
         AJ(3 + J, M) = -W(OFFH + J)
   60 CONTINUE
      DO 70 B = 1, 3
         AJ(M, B) = W(OFFDF + B)
   70 CONTINUE
      DO 80 K = 1, NQV
         AJ(M, 3 + K) = W(OFFDFQ + K)
   80 CONTINUE
      AJ(M, M) = 0.0D0
      RETURN
      END
C ----------------------------------------------------------------------
C LU factorization with partial pivoting in place; .FALSE. if singular.
      LOGICAL FUNCTION @P@LU(AJ, IPIV)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION AJ(M, M), BEST, T, AINV, AL
      INTEGER IPIV(M), C, R, K, J
      @P@LU = .FALSE.
      DO 50 C = 1, M
         BEST = ABS(AJ(C, C))
         K = C
         DO 10 R = C + 1, M
            IF (ABS(AJ(R, C)) .GT. BEST) THEN
               BEST = ABS(AJ(R, C))
               K = R
            END IF
   10    CONTINUE
         IPIV(C) = K
         IF (BEST .EQ. 0.0D0 .OR. .NOT. (BEST .LE. HUGE(1.0D0))) RETURN
         IF (K .NE. C) THEN
            DO 20 J = 1, M
               T = AJ(C, J)
               AJ(C, J) = AJ(K, J)
               AJ(K, J) = T
   20       CONTINUE
         END IF
         AINV = 1.0D0/AJ(C, C)
         DO 40 R = C + 1, M
            AJ(R, C) = AJ(R, C)*AINV
            AL = AJ(R, C)
            IF (AL .NE. 0.0D0) THEN
               DO 30 J = C + 1, M
                  AJ(R, J) = AJ(R, J) - AL*AJ(C, J)
   30          CONTINUE
            END IF
   40    CONTINUE
   50 CONTINUE
      @P@LU = .TRUE.
      RETURN
      END
C ----------------------------------------------------------------------
C Solve with the LU factors; B overwritten by the solution.
      SUBROUTINE @P@LS(AJ, IPIV, B)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION AJ(M, M), B(M), T, ACC
      INTEGER IPIV(M), C, K, R, J
      DO 10 C = 1, M
         K = IPIV(C)
         IF (K .NE. C) THEN
            T = B(C)
            B(C) = B(K)
            B(K) = T
         END IF
   10 CONTINUE
      DO 30 R = 2, M
         ACC = B(R)
         DO 20 J = 1, R - 1
            ACC = ACC - AJ(R, J)*B(J)
   20    CONTINUE
         B(R) = ACC
   30 CONTINUE
      DO 50 R = M, 1, -1
         ACC = B(R)
         DO 40 J = R + 1, M
            ACC = ACC - AJ(R, J)*B(J)
   40    CONTINUE
         B(R) = ACC/AJ(R, R)
   50 CONTINUE
      RETURN
      END
C ----------------------------------------------------------------------
C Newton return of STR onto f = 0 from X = (STR, QN, 0); .TRUE. if it
C converged. Leaves the last iterate in X, the law's quantities in W.
      LOGICAL FUNCTION @P@NR(STR, QN, P, DV, X, W)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION STR(3), QN(NQS), P(*), DV(3), X(M), W(*)
      DOUBLE PRECISION XK(M), ROWS(M), COLS(M), R(M), RK(M), STEP(M)
      DOUBLE PRECISION AJ(M, M), WK(NSIZE), F, DFN, FS, GS, ALAMS, QS
      DOUBLE PRECISION AMERIT, AMK, ALPHA
      INTEGER IPIV(M), A, B, J, K, IT, IH, NQV
      LOGICAL FULL, ACCEPT
      DOUBLE PRECISION @P@RS
      LOGICAL @P@LU
      EXTERNAL @P@RS, @P@LU
      NQV = NQ
      @P@NR = .FALSE.
      FULL = .TRUE.
      DO 5 K = 1, NSIZE
         WK(K) = 0.0D0
    5 CONTINUE
      F = MAX(SQRT(STR(1)**2 + STR(2)**2 + STR(3)**2), 1.0D-300)
      CALL @P@EV(STR(1), STR(2), STR(3), QN, P, W, 2)
      DFN = SQRT(W(OFFDF + 1)**2 + W(OFFDF + 2)**2 + W(OFFDF + 3)**2)
      FS = MAX(DFN*F, 1.0D-300)
      GS = MAX(SQRT((DV(1)*W(OFFDG + 1))**2 + (DV(2)*W(OFFDG + 2))**2
     &     + (DV(3)*W(OFFDG + 3))**2), 1.0D-300)
      ALAMS = F/GS
      DO 10 A = 1, 3
         ROWS(A) = 1.0D0/F
         COLS(A) = F
         X(A) = STR(A)
   10 CONTINUE
      DO 20 J = 1, NQV
         QS = MAX(MAX(ABS(W(OFFH + J))*ALAMS, ABS(QN(J))), 1.0D-300)
         ROWS(3 + J) = 1.0D0/QS
         COLS(3 + J) = QS
         X(3 + J) = QN(J)
   20 CONTINUE
      ROWS(M) = 1.0D0/FS
      COLS(M) = ALAMS
      X(M) = 0.0D0
      AMERIT = @P@RS(W, X, STR, QN, DV, ROWS, R)
      DO 90 IT = 1, @MAX_ITER@
         IF (AMERIT .LE. @TOL@) GO TO 100
         IF (.NOT. FULL) CALL @P@EV(X(1), X(2), X(3), X(4), P, W, 2)
         CALL @P@JA(W, X(M), DV, AJ)
         DO 35 B = 1, M
            DO 30 A = 1, M
               AJ(A, B) = AJ(A, B)*ROWS(A)*COLS(B)
   30       CONTINUE
   35    CONTINUE
         IF (.NOT. @P@LU(AJ, IPIV)) RETURN
         DO 40 A = 1, M
            STEP(A) = -R(A)
   40    CONTINUE
         CALL @P@LS(AJ, IPIV, STEP)
         DO 50 A = 1, M
            STEP(A) = STEP(A)*COLS(A)
   50    CONTINUE
         ALPHA = 1.0D0
         ACCEPT = .FALSE.
         DO 80 IH = 1, @MAX_HALVINGS@
            DO 60 A = 1, M
               XK(A) = X(A) + ALPHA*STEP(A)
   60       CONTINUE
            CALL @P@EV(XK(1), XK(2), XK(3), XK(4), P, WK, 1)
            AMK = @P@RS(WK, XK, STR, QN, DV, ROWS, RK)
            IF (AMK .LE. (1.0D0 - @SUFFICIENT_DECREASE@*ALPHA)*AMERIT) THEN
               DO 70 A = 1, M
                  X(A) = XK(A)
                  R(A) = RK(A)
   70          CONTINUE
               DO 75 K = 1, NSIZE
                  W(K) = WK(K)
   75          CONTINUE
               AMERIT = AMK
               FULL = .FALSE.
               ACCEPT = .TRUE.
               GO TO 85
            END IF
            ALPHA = 0.5D0*ALPHA
   80    CONTINUE
   85    IF (.NOT. ACCEPT) RETURN
   90 CONTINUE
  100 @P@NR = AMERIT .LE. @TOL@ .AND. X(M) .GE. 0.0D0
      RETURN
      END
C ----------------------------------------------------------------------
C Trial forces whose return ends at the apex SIGMA = 0 of a cone.
      LOGICAL FUNCTION @P@AX(STR, Q, P, DV, W)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION STR(3), Q(NQS), P(*), DV(3), W(*), GT, TT
      @P@AX = .FALSE.
      CALL @P@EV(0.0D0, 0.0D0, 0.0D0, Q, P, W, 0)
      IF (W(1) .NE. 0.0D0) RETURN
      CALL @P@EV(STR(1), STR(2), 0.0D0, Q, P, W, 1)
      GT = SQRT(W(OFFDG + 1)**2 + W(OFFDG + 2)**2)
      TT = SQRT(STR(1)**2 + STR(2)**2)
      @P@AX = W(OFFDG + 3) .GT. 0.0D0 .AND.
     &     STR(3)*DV(1)*GT .LE. TT*DV(3)*W(OFFDG + 3)
      RETURN
      END
C ----------------------------------------------------------------------
C The return of closed trial forces STR (STR(3) > 0) at the stiffnesses
C DV: KIND = KELAS (SIG = STR), KPLAS (SIG, Q1, DLAM and, when WANT,
C DSIG = dSIGMA/dSIGMA_trial), KAPEX (apex of a cone) or KFAIL.
      SUBROUTINE @P@RM(STR, QN, P, DV, SIG, Q1, DLAM, DSIG, WANT, KIND)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION STR(3), QN(NQS), P(*), DV(3), SIG(3), Q1(NQS)
      DOUBLE PRECISION DLAM, DSIG(3, 3), X(M), W(NSIZE), AJ(M, M)
      DOUBLE PRECISION COL(M), ANTR
      INTEGER KIND, IPIV(M), A, C, J, NQV
      LOGICAL WANT, @P@NR, @P@AX, @P@LU
      EXTERNAL @P@NR, @P@AX, @P@LU
      NQV = NQ
      ANTR = SQRT(STR(1)**2 + STR(2)**2 + STR(3)**2)
      DO 10 J = 1, NQV
         Q1(J) = QN(J)
   10 CONTINUE
      DO 20 A = 1, 3
         SIG(A) = STR(A)
   20 CONTINUE
      DLAM = 0.0D0
      KIND = KELAS
      CALL @P@EV(STR(1), STR(2), STR(3), QN, P, W, 0)
      IF (W(1) .LE. 0.0D0) RETURN
      IF (.NOT. @P@NR(STR, QN, P, DV, X, W)) THEN
         KIND = KFAIL
         IF (STR(3) .LE. @TOL@*ANTR) KIND = KAPEX
         IF (KIND .EQ. KFAIL) THEN
            IF (@P@AX(STR, QN, P, DV, W)) KIND = KAPEX
         END IF
         RETURN
      END IF
      DLAM = X(M)
      KIND = KAPEX
      IF (X(3) .LT. 0.0D0) RETURN
      IF (SQRT(X(1)**2 + X(2)**2 + X(3)**2) .LE. @TOL@*ANTR) RETURN
      KIND = KPLAS
      DO 30 A = 1, 3
         SIG(A) = X(A)
   30 CONTINUE
      DO 40 J = 1, NQV
         Q1(J) = X(3 + J)
   40 CONTINUE
      IF (.NOT. WANT) RETURN
      CALL @P@EV(X(1), X(2), X(3), X(4), P, W, 2)
      CALL @P@JA(W, DLAM, DV, AJ)
      IF (.NOT. @P@LU(AJ, IPIV)) THEN
         KIND = KFAIL
         RETURN
      END IF
      DO 70 C = 1, 3
         DO 50 A = 1, M
            COL(A) = 0.0D0
   50    CONTINUE
         COL(C) = 1.0D0
         CALL @P@LS(AJ, IPIV, COL)
         DO 60 A = 1, 3
            DSIG(A, C) = COL(A)
   60    CONTINUE
   70 CONTINUE
      RETURN
      END
"""
